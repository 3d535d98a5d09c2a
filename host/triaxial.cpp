#include "triaxial.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "host/membrane_mesh.hpp"
#include "job.hpp"
#include "progress.hpp"
#include "servo.hpp"
#include "simulation.hpp"

namespace dem {

namespace {

enum Platen { kBottomPlaten = 0, kTopPlaten = 1 };

/// The test cell: two platens, the membrane (sides tangent to the mould, so no ball starts inside a
/// facet) and the specimen's balls.
struct Cell {
  std::unique_ptr<Simulation> sim;
  Membrane membrane;
  Real radius = 0, area = 0;  ///< m, m^2: mould radius and platen area
  Real kn_wall = 0;           ///< N/m, platen contact stiffness of a mean ball
  Real solid_volume = 0;      ///< m^3
};

Cell make_cell(const Config& cfg, const Specimen& sp) {
  const TriaxialConfig& tc = cfg.triaxial;
  Cell c;
  c.radius = cfg.specimen.diameter / 2;
  c.area = M_PI * c.radius * c.radius;
  const Real r_nodes = c.radius / std::cos(M_PI / tc.membrane_around);
  MembraneMaterial mat;
  mat.young = tc.membrane_modulus;
  mat.poisson = tc.membrane_poisson;
  mat.thickness = tc.membrane_thickness;
  mat.density = tc.membrane_density;
  c.membrane = make_membrane(make_cylinder_membrane(tc.membrane_around, tc.membrane_segments, r_nodes, 0, sp.height),
                             mat, 1);
  std::vector<WallSpec> w(2);
  w[kBottomPlaten].normal = Vec3(0, 0, 1);
  w[kTopPlaten].point = Vec3(0, 0, sp.height);
  w[kTopPlaten].normal = Vec3(0, 0, -1);
  for (auto& x : w) x.material = 1;
  const SimParams prm = solver_params(cfg);
  c.sim = std::make_unique<Simulation>(make_particles(sp.balls), make_walls(w), c.membrane.mesh,
                                       std::vector<ContactParams>{cfg.ball, cfg.wall, cfg.wall, cfg.wall}, 2, prm);
  MembraneIntegrateParams mp;
  mp.gravity = prm.integ.gravity;
  mp.alpha = cfg.solver.damping;
  mp.mass_scale = cfg.solver.mass_scale;
  c.sim->set_membrane(c.membrane, mp);
  c.sim->set_cell_pressure(cfg.triaxial.sigma3);
  c.sim->set_dt(cfg.solver.dt > 0 ? cfg.solver.dt : cfg.solver.dt_safety * c.sim->critical_dt());
  c.kn_wall = NormalLinear::stiffness(cfg.wall, cfg.particles.diameter / 2, 0);
  for (const BallSpec& b : sp.balls) c.solid_volume += 4.0 / 3.0 * M_PI * b.radius * b.radius * b.radius;
  return c;
}

/// Moves the top platen and the membrane's top ring together (the ring is tied to the platen).
void set_top_velocity(Cell& c, Real vz) {
  c.sim->set_wall_velocity(kTopPlaten, Vec3(0, 0, vz));
  auto ring = c.membrane.ring_top;
  auto v = c.membrane.mesh.node_v;
  Kokkos::parallel_for("dem::triaxial::tie_ring", RangePolicy(0, ring.extent(0)), KOKKOS_LAMBDA(const int k) {
    v(ring(k), 0) = 0;
    v(ring(k), 1) = 0;
    v(ring(k), 2) = vz;
  });
}

/// Axial stresses on the two platens (Pa, compression positive).
std::pair<Real, Real> platen_stresses(Cell& c) {
  const std::vector<Vec3> f = c.sim->wall_forces();
  return {f[kTopPlaten].z / c.area, -f[kBottomPlaten].z / c.area};
}

Real specimen_volume(const Cell& c) { return enclosed_volume(c.membrane, 0, c.sim->wall_point(kTopPlaten).z); }

/// Balls whose centre lies outside the membrane: radius above the local ring radius (mean radius of the
/// two rings around the ball's height, interpolated).
int count_escaped(Cell& c, int n_around) {
  auto nx = Kokkos::create_mirror_view_and_copy(HostSpace(), c.membrane.mesh.node_x);
  const int nring = c.membrane.nnode / n_around;
  std::vector<Real> zr(nring, 0), rr(nring, 0);
  for (int r = 0; r < nring; ++r)
    for (int k = 0; k < n_around; ++k) {
      const int q = r * n_around + k;
      zr[r] += nx(q, 2) / n_around;
      rr[r] += std::hypot(nx(q, 0), nx(q, 1)) / n_around;
    }
  const HostParticles h = to_host_by_gid(c.sim->particles());
  int out = 0;
  for (const Vec3& x : h.x) {
    const int r = std::clamp(static_cast<int>(std::upper_bound(zr.begin(), zr.end(), x.z) - zr.begin()) - 1, 0,
                             nring - 2);
    const Real t = std::clamp((x.z - zr[r]) / (zr[r + 1] - zr[r]), Real(0), Real(1));
    if (std::hypot(x.x, x.y) > (1 - t) * rr[r] + t * rr[r + 1] || x.z < zr.front() || x.z > zr.back()) ++out;
  }
  return out;
}

}  // namespace

TriaxialResult run_triaxial(const Config& cfg, const Specimen& sp, io::Output* out, bool verbose) {
  const auto t0 = std::chrono::steady_clock::now();
  const TriaxialConfig& tc = cfg.triaxial;
  Cell cell = make_cell(cfg, sp);
  Simulation& sim = *cell.sim;
  const Real dt = sim.params().integ.dt;
  TriaxialResult res;

  // Isotropic consolidation: cell pressure on the membrane, stress servo on the top platen.
  StressServo servo;
  servo.target = tc.sigma3;
  servo.area = cell.area;
  servo.v_max = 0.05 * sp.height / (2000 * dt);  // at most 5% of the height in 2000 steps
  Progress cons("consolidation", tc.max_consolidation_steps);
  long s = 0;
  for (; s < tc.max_consolidation_steps; ++s) {
    const auto [top, bottom] = platen_stresses(cell);
    const int n = sim.wall_contact_counts()[kTopPlaten];
    set_top_velocity(cell, -servo.speed(top, n * cell.kn_wall, dt));
    const bool check = (s + 1) % 200 == 0;
    sim.step(check);
    if (!check) continue;
    const Real ratio = sim.unbalanced_ratio();
    // The servo holds the top platen; the bottom one differs by what the membrane carries through
    // friction and its own axial stiffness, so only the controlled stress decides.
    const Real err = std::fabs(top - tc.sigma3) / tc.sigma3;
    if (verbose) {
      char extra[96];
      std::snprintf(extra, sizeof extra, "sigma_top %.1f kPa, sigma_bottom %.1f kPa, unbalanced %.1e", top / 1e3,
                    bottom / 1e3, ratio);
      cons.update(s + 1, extra);
    }
    if (err < tc.consolidation_tol && ratio < tc.stop_ratio) break;
  }
  if (s >= tc.max_consolidation_steps)
    throw ConfigError(cfg.path + ": [triaxial] max_consolidation_steps: consolidation to " +
                      std::to_string(tc.sigma3 / 1e3) + " kPa did not settle within " +
                      std::to_string(tc.max_consolidation_steps) + " steps");
  res.consolidation_steps = s + 1;
  const Real h0 = sim.wall_point(kTopPlaten).z;
  const Real v0 = specimen_volume(cell);
  res.void_ratio_consolidated = v0 / cell.solid_volume - 1;
  if (verbose)
    std::printf("\nconsolidated at %.0f kPa: e = %.4f, height %.3f mm after %ld steps\n", tc.sigma3 / 1e3,
                res.void_ratio_consolidated, h0 * 1e3, res.consolidation_steps);

  // Shear: constant platen speed from the inertial number (density scaling counts in rho).
  const Real rho = cfg.particles.density * cfg.solver.mass_scale;
  res.shear_rate = tc.inertial_number / (cfg.particles.diameter * std::sqrt(rho / tc.sigma3));
  res.inertial_number = tc.inertial_number;
  set_top_velocity(cell, -res.shear_rate * h0);
  const long steps = static_cast<long>(std::ceil(tc.axial_strain_end / (res.shear_rate * dt)));
  if (verbose)
    std::printf("shear: strain rate %.3g 1/s (inertial number %.1e%s), %ld steps to %.0f%%\n", res.shear_rate,
                tc.inertial_number, cfg.solver.mass_scale != 1 ? ", with density scaling" : "", steps,
                tc.axial_strain_end * 100);
  if (out)
    out->set_series_columns({"eps_a_pct", "eps_v_pct", "q_kPa", "sigma1_kPa", "sigma1_bottom_kPa", "sigma3_kPa",
                             "unbalanced_ratio", "kinetic_energy_J"});
  const Real snaps[] = {0.0, 0.01, 0.05, tc.axial_strain_end};
  int next_snap = 0;
  Real next_record = 0;
  Progress shear("shear", steps);
  for (long k = 0; k <= steps; ++k) {
    const Real eps_a = (h0 - sim.wall_point(kTopPlaten).z) / h0;
    if (eps_a >= next_record - 1e-12 || k == steps) {
      TriaxialRecord r;
      const auto [top, bottom] = platen_stresses(cell);
      r.eps_a = eps_a;
      r.eps_v = (v0 - specimen_volume(cell)) / v0;
      r.sigma1 = top;
      r.sigma1_bottom = bottom;
      r.q = top - tc.sigma3;
      r.unbalanced = sim.unbalanced_ratio();
      r.kinetic = sim.stats().kinetic;
      res.records.push_back(r);
      if (out)
        out->append_series({100 * r.eps_a, 100 * r.eps_v, r.q / 1e3, r.sigma1 / 1e3, r.sigma1_bottom / 1e3,
                            tc.sigma3 / 1e3, r.unbalanced, r.kinetic});
      next_record += tc.record_every;
      if (verbose) {
        char extra[64];
        std::snprintf(extra, sizeof extra, "eps_a %.2f%%, q %.1f kPa", 100 * eps_a, r.q / 1e3);
        shear.update(k, extra);
      }
    }
    if (out && next_snap < 4 && eps_a >= snaps[next_snap] - 1e-12) {
      char label[48];
      std::snprintf(label, sizeof label, "shear eps_a=%.0f%%", 100 * snaps[next_snap]);
      out->write_snapshot(take_snapshot(sim, label));
      ++next_snap;
    }
    if (k == steps) break;
    sim.step(true);
  }
  if (out) out->flush_series();
  for (std::size_t i = 0; i < res.records.size(); ++i) {
    const TriaxialRecord& r = res.records[i];
    if (r.q > res.q_peak) {
      res.q_peak = r.q;
      res.eps_a_peak = r.eps_a;
      res.phi_peak_deg = std::asin(r.q / (r.q + 2 * tc.sigma3)) * 180 / M_PI;
    }
    if (i > 0 && r.eps_a > res.records[i - 1].eps_a)
      res.max_dilatancy = std::max(res.max_dilatancy, -(r.eps_v - res.records[i - 1].eps_v) /
                                                          (r.eps_a - res.records[i - 1].eps_a));
  }
  if (!res.records.empty()) res.q_end = res.records.back().q;
  res.escaped = count_escaped(cell, tc.membrane_around);
  res.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

int triaxial_job(const Config& cfg) {
  if (!cfg.has_specimen) throw ConfigError(cfg.path + ": [specimen]: table missing (the triaxial job needs it)");
  io::Output out(cfg.run.output);
  try {
    const Specimen sp = build_specimen(cfg, true);
    const TriaxialResult r = run_triaxial(cfg, sp, &out, true);
    std::printf("\nresult: q_peak %.1f kPa at eps_a %.2f%%, peak friction angle %.1f deg, q at %.0f%% %.1f kPa, "
                "max dilatancy %.3f, wall time %s\n",
                r.q_peak / 1e3, 100 * r.eps_a_peak, r.phi_peak_deg, 100 * cfg.triaxial.axial_strain_end,
                r.q_end / 1e3, r.max_dilatancy, format_duration(r.wall_seconds).c_str());
    if (r.escaped > 0) std::printf("WARNING: %d balls ended outside the membrane\n", r.escaped);
    std::printf("output: %s/series.csv, %s/snapshots.xdmf\n", out.folder().c_str(), out.folder().c_str());
  } catch (const BlowUp& e) {
    std::fprintf(stderr, "\ntriaxdem: %s\n", e.what());
    return 2;
  }
  return 0;
}

}  // namespace dem
