#include "host/triax/periodic_triaxial.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

#include "host/triax/cell_boundary.hpp"
#include "host/data/measured.hpp"
#include "kernels/core/reduce.hpp"
#include "host/engine/setup.hpp"
#include "host/engine/stage_loop.hpp"
#include "host/util/progress.hpp"

namespace dem {

namespace {

constexpr Real kPi = 3.14159265358979323846;

/// Mean diameter (m), effective density (kg/m^3, x mass_scale) and solid volume (m^3) of the balls.
struct GrainScales {
  Real d = 0, rho_eff = 0, v_solid = 0;
};

GrainScales grain_scales(Simulation& sim) {
  Particles& p = sim.particles();
  auto r = Kokkos::create_mirror_view_and_copy(HostSpace(), p.radius);
  auto m = Kokkos::create_mirror_view_and_copy(HostSpace(), p.mass);
  GrainScales g;
  Real mass = 0;
  for (int i = 0; i < p.n; ++i) {
    g.d += 2 * r(i);
    g.v_solid += 4.0 / 3.0 * kPi * r(i) * r(i) * r(i);
    mass += m(i);
  }
  if (p.n > 0) g.d /= p.n;
  g.rho_eff = g.v_solid > 0 ? mass / g.v_solid * sim.params().integ.mass_scale : 0;
  return g;
}

/// The strain-rate servo of the cell: each call measures the contact stress and sets the next step's rates.
class CellServo {
 public:
  CellServo(const PeriodicTriaxialParams& prm, Real max_rate) : prm_(prm), max_rate_(max_rate) {}

  /// servo[d]: axis d is servoed to target[d] (Pa); otherwise its rate is fixed[d] (1/s, extension positive).
  void update(Simulation& sim, const bool servo[3], const Real fixed[3], const Real target[3]) {
    if (calls_++ % prm_.stiffness_every == 0) k_ = boundary_stiffness(sim);
    stress_ = cell_stress(sim);
    const Real dt = sim.params().integ.dt;
    Real rate[3];
    for (int d = 0; d < 3; ++d) {
      if (!servo[d]) { rate[d] = fixed[d]; continue; }
      const Real err = stress_[d] - target[d];
      // gain = alpha sigma3 / (K dt); with no contacts (K = 0) the clamp decides.
      const Real r = k_[d] > 0 ? prm_.servo_alpha * err / (k_[d] * dt)
                               : (err > 0 ? max_rate_ : (err < 0 ? -max_rate_ : Real(0)));
      rate[d] = std::clamp(r, -max_rate_, max_rate_);
    }
    set_cell_rates(sim, Vec3(rate[0], rate[1], rate[2]));
  }

 private:
  const PeriodicTriaxialParams& prm_;
  Real max_rate_;
  long calls_ = 0;
  std::array<Real, 3> k_{};
  std::array<Real, 3> stress_{};
};

/// Lateral confinement per axis: sigma3 plus the membrane's, from the cell's lateral strains since L0.
std::array<Real, 3> lateral_targets(const std::array<Real, 3>& lengths, const PeriodicTriaxialParams& prm,
                                    const std::array<Real, 3>& L0) {
  std::array<Real, 3> t{};
  for (int d = 0; d < 3; ++d)
    t[d] = prm.sigma3 + membrane_confinement(prm.membrane_stiffness, lengths[d] / L0[d] - 1);
  return t;
}

PeriodicTriaxialRecord measure_row(Simulation& sim, const PeriodicTriaxialParams& prm, const GrainScales& g,
                                   Real h0, Real V0, const std::array<Real, 3>& L0) {
  PeriodicTriaxialRecord r;
  const std::array<Real, 3> lengths = cell_lengths(sim);
  const Real V = cell_volume(sim);
  const std::array<Real, 3> s = cell_stress(sim);
  r.step = sim.step_count();
  r.time = sim.time();
  r.eps_a = (h0 - lengths[2]) / h0;
  r.eps_v = -(V - V0) / V0;
  r.sigma1 = s[2];
  r.sigma2 = s[0];
  r.sigma3 = s[1];
  const Real lateral = 0.5 * (r.sigma2 + r.sigma3);
  const std::array<Real, 3> target = lateral_targets(lengths, prm, L0);
  r.membrane = 0.5 * (target[0] + target[1]) - prm.sigma3;
  r.q = r.sigma1 - (lateral - r.membrane);
  r.p = (r.sigma1 + r.sigma2 + r.sigma3) / 3;
  const Real sum = r.sigma1 + lateral;
  r.phi_mob_deg = sum > 0 ? std::asin(std::clamp(r.q / sum, Real(-1), Real(1))) * 180 / kPi : 0;
  r.void_ratio = V / g.v_solid - 1;
  const int n = sim.particles().n;
  r.coordination = n > 0 ? 2.0 * static_cast<Real>(sim.touching()[0]) / n : 0;
  r.unbalanced = sim.unbalanced_ratio();
  r.kinetic = sim.stats().kinetic;
  r.inertial = r.p > 0 ? prm.axial_rate * g.d * std::sqrt(g.rho_eff / r.p) : std::numeric_limits<Real>::infinity();
  const Vec3 rates = cell_rates(sim);
  r.rate_x = rates.x;
  r.rate_y = rates.y;
  return r;
}

const std::vector<std::string> kSeriesColumns = {
    "step", "time_s", "eps_a_pct", "eps_v_pct", "sigma1_kPa", "sigma2_kPa", "sigma3_kPa", "q_kPa", "p_kPa",
    "phi_mob_deg", "void_ratio", "coordination", "unbalanced_ratio", "kinetic_energy_J", "inertial_number",
    "rate_x_per_s", "rate_y_per_s", "membrane_kPa"};

std::vector<double> series_row(const PeriodicTriaxialRecord& r) {
  return {static_cast<double>(r.step), r.time, 100 * r.eps_a, 100 * r.eps_v, 1e-3 * r.sigma1, 1e-3 * r.sigma2,
          1e-3 * r.sigma3, 1e-3 * r.q, 1e-3 * r.p, r.phi_mob_deg, r.void_ratio, r.coordination, r.unbalanced,
          r.kinetic, r.inertial, r.rate_x, r.rate_y, 1e-3 * r.membrane};
}

std::string pct_label(Real eps) {
  char b[48];
  std::snprintf(b, sizeof b, "shear eps_a=%g%%", 100 * eps);
  return b;
}

}  // namespace

std::array<Real, 3> cell_stiffness(Simulation& sim) {
  const ContactList c = sim.ball_contacts();
  Particles& p = sim.particles();
  auto x = p.x;
  auto r = p.radius;
  const Domain dom = sim.domain();
  Real k[3];
  deterministic_reduce<3, 0>("dem::periodic::cell_stiffness", c.n, KOKKOS_LAMBDA(const int s, Real* v) {
    const Real fn = c.fn(s);
    if (!(fn > 0)) return;
    const Vec3 l = dom.min_image(load(x, c.j(s)) - load(x, c.i(s)));
    const Real overlap = r(c.i(s)) + r(c.j(s)) - norm(l);
    if (!(overlap > 0)) return;
    const Real kn = fn / overlap;
    v[0] = kn * l.x * l.x;
    v[1] = kn * l.y * l.y;
    v[2] = kn * l.z * l.z;
  }, k);
  const Real V = dom.volume();
  return {k[0] / V, k[1] / V, k[2] / V};
}

PeriodicTriaxialParams resolve_periodic_params(Simulation& sim, PeriodicTriaxialParams prm) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("periodic triaxial: " + what); };
  const Domain& dom = sim.domain();
  const bool periodic = dom.periodic[0] && dom.periodic[1] && dom.periodic[2];
  if (!periodic && !walled(sim)) bad("the cell must be periodic along x, y and z, or lie between six walls");
  if ((periodic && sim.num_walls() > 0) || sim.membrane().ntri > 0)
    bad("a periodic cell must have no walls, facets or membrane");
  if (norm2(sim.params().integ.gravity) != 0) bad("gravity must be zero in a fully periodic cell");
  if (sim.params().integ.dt <= 0) bad("the time step is not set");
  if (!(prm.sigma3 > 0)) bad("sigma3 must be > 0");
  if (!(prm.target_strain > 0 && prm.target_strain < 0.9)) bad("target axial strain must be in (0, 0.9)");
  if (!(prm.servo_alpha > 0 && prm.servo_alpha <= 1)) bad("servo alpha must be in (0, 1]");
  if (!(prm.stress_tolerance > 0 && prm.unbalanced_tolerance > 0)) bad("tolerances must be > 0");
  if (!(prm.record_strain > 0)) bad("record strain interval must be > 0");
  if (prm.axial_rate < 0 || prm.max_lateral_rate < 0 || prm.consolidation_rate < 0) bad("rates must be >= 0");
  if (prm.check_every < 1 || prm.stiffness_every < 1 || prm.max_consolidation_steps < 1)
    bad("check_every, stiffness_every and max_consolidation_steps must be >= 1");
  const GrainScales g = grain_scales(sim);
  const Real scale = g.d * std::sqrt(g.rho_eff / prm.sigma3);  // I = rate * scale at p = sigma3
  if (prm.axial_rate == 0) {
    if (!(prm.target_inertial > 0)) bad("target inertial number must be > 0 when the axial rate is automatic");
    prm.axial_rate = prm.target_inertial / scale;
  }
  const Real inertial = prm.axial_rate * scale;
  if (inertial > prm.max_inertial && !prm.allow_high_inertial) {
    std::ostringstream s;
    s << "axial strain rate " << prm.axial_rate << " /s gives an inertial number I = " << inertial
      << " at p = sigma3, above the quasi-static limit " << prm.max_inertial << " (d = " << g.d
      << " m, rho_eff = " << g.rho_eff << " kg/m^3); lower the rate to at most " << prm.max_inertial / scale
      << " /s or set allow_high_inertial";
    bad(s.str());
  }
  if (prm.max_lateral_rate == 0) prm.max_lateral_rate = 5 * prm.axial_rate;
  if (prm.consolidation_rate == 0) prm.consolidation_rate = prm.max_lateral_rate;
  return prm;
}

StageEnd consolidate_isotropic(Simulation& sim, const PeriodicTriaxialParams& prm_in) {
  const PeriodicTriaxialParams prm = resolve_periodic_params(sim, prm_in);  // idempotent
  CellServo servo(prm, prm.consolidation_rate);
  const bool all[3] = {true, true, true};
  const Real none[3] = {0, 0, 0};
  Progress progress(prm.name + " consolidation (ETA to the step cap)", prm.max_consolidation_steps);
  Real err = 0, ratio = 1;
  std::array<Real, 3> s{};
  StageSteps stage;
  stage.last = prm.max_consolidation_steps;
  stage.before = [&](long n) {
    const Real target[3] = {prm.sigma3, prm.sigma3, prm.sigma3};
    servo.update(sim, all, none, target);
    return StepPlan{false, n % prm.check_every == 0};
  };
  stage.after = [&](long n, bool measured) {
    if (!measured) return false;
    s = cell_stress(sim);
    err = 0;
    for (int d = 0; d < 3; ++d) err = std::max(err, std::fabs(s[d] - prm.sigma3) / prm.sigma3);
    ratio = sim.unbalanced_ratio();
    if (prm.verbose) {
      char extra[128];
      std::snprintf(extra, sizeof extra, "p %.1f kPa, stress error %.2e, unbalanced %.2e",
                    1e-3 * (s[0] + s[1] + s[2]) / 3, err, ratio);
      progress.update(n, extra);
    }
    return err < prm.stress_tolerance && ratio < prm.unbalanced_tolerance;
  };
  StageEnd end = run_stage(sim, stage, nullptr);
  set_cell_rates(sim, Vec3());
  if (end.done) {
    if (prm.verbose) progress.finish("(converged after " + std::to_string(end.step) + " steps)");
    end.timing.name = "consolidation";
    return end;
  }
  std::ostringstream msg;
  msg << "periodic triaxial: isotropic consolidation to sigma3 = " << 1e-3 * prm.sigma3 << " kPa did not converge in "
      << prm.max_consolidation_steps << " steps: stresses (xx, yy, zz) = (" << 1e-3 * s[0] << ", " << 1e-3 * s[1]
      << ", " << 1e-3 * s[2] << ") kPa, largest error " << err << " (tolerance " << prm.stress_tolerance
      << "), unbalanced-force ratio " << ratio << " (tolerance " << prm.unbalanced_tolerance
      << "). Raise max_consolidation_steps, or loosen unbalanced_tolerance if the ratio is still falling";
  throw std::runtime_error(msg.str());
}

namespace {

/// The result's curve values and checks (the lateral stress's largest error, the largest kinetic energy), and the
/// closing lines when verbose; `wall_seconds` is set.
void finish_result(const Simulation& sim, PeriodicTriaxialResult& res, Progress& progress, double wall_seconds) {
  const PeriodicTriaxialParams& prm = res.params;
  take_curve_values(res, summarised(res.series, prm.sigma3));
  for (const PeriodicTriaxialRecord& r : res.series) {
    // The membrane's share is the same on both axes to rounding (they stretch alike on average); its
    // mean is recorded.
    const Real target = prm.sigma3 + r.membrane;
    res.max_lateral_error = std::max({res.max_lateral_error, std::fabs(r.sigma2 - target) / target,
                                      std::fabs(r.sigma3 - target) / target});
    res.max_kinetic = std::max(res.max_kinetic, r.kinetic);
  }
  res.wall_seconds = wall_seconds;
  if (prm.verbose) {
    const PeriodicTriaxialRecord& f = res.series.back();
    progress.finish("");
    std::printf("periodic triaxial: consolidated in %ld steps to void ratio %.4f (Z = %.2f); sheared to eps_a = %.2f%% "
                "in %ld steps\n", res.consolidation_steps, res.void_ratio0, res.series.front().coordination,
                100 * f.eps_a, sim.step_count() - res.series.front().step);
    std::printf("peak q = %.2f kPa at eps_a = %.2f%% (moving mean over +-%.2f%% strain); peak friction angle "
                "phi = asin((s1-s3)/(s1+s3)) = %.2f deg\n",
                1e-3 * res.q_peak, 100 * res.eps_a_peak, 100 * kSmoothHalfWidth, res.phi_peak_deg);
    std::printf("end: q = %.2f kPa, eps_v = %.2f%%, void ratio %.4f; lateral stress within %.2f%% of sigma3; "
                "wall time %s\n", 1e-3 * f.q, 100 * f.eps_v, f.void_ratio, 100 * res.max_lateral_error,
                format_duration(res.wall_seconds).c_str());
  }
}

/// The test's first line: pressure, rate, inertial number (flagged above the quasi-static limit), step, servo.
void announce(const PeriodicTriaxialParams& prm, Real inertial, Real dt) {
  std::printf("periodic triaxial: sigma3 %.1f kPa, axial rate %.4g /s (I = %.2e at p = sigma3%s), dt %.3e s, "
              "servo alpha %.2f, lateral rate clamp %.4g /s\n",
              1e-3 * prm.sigma3, prm.axial_rate, inertial,
              inertial > prm.max_inertial ? ", ABOVE the quasi-static limit: allowed by the config" : "", dt,
              prm.servo_alpha, prm.max_lateral_rate);
}

/// Snapshots at the configured axial strains within the test, each written once, when the strain first reaches it
/// (several passed in one step give one snapshot, labelled with the largest).
class SnapshotSchedule {
 public:
  SnapshotSchedule(const PeriodicTriaxialParams& prm, Simulation& sim, io::Output* out) : sim_(sim), out_(out) {
    for (Real e : prm.snapshot_strains)
      if (e >= 0 && e <= prm.target_strain + 1e-12) strains_.push_back(e);
    std::sort(strains_.begin(), strains_.end());
  }
  /// The cell is at axial strain eps.
  void at(Real eps) {
    Real nominal = -1;
    while (next_ < strains_.size() && eps >= strains_[next_] - 1e-9) nominal = strains_[next_++];
    if (nominal >= 0 && out_) {
      out_->flush_series();
      out_->write_snapshot(take_snapshot(sim_, pct_label(nominal)));
    }
  }

 private:
  Simulation& sim_;
  io::Output* out_;
  std::vector<Real> strains_;
  std::size_t next_ = 0;
};

}  // namespace

PeriodicTriaxialResult run_periodic_triaxial(Simulation& sim, const PeriodicTriaxialParams& prm_in, io::Output* out) {
  const auto t0 = std::chrono::steady_clock::now();
  PeriodicTriaxialResult res;
  res.params = resolve_periodic_params(sim, prm_in);
  const PeriodicTriaxialParams& prm = res.params;
  const GrainScales g = grain_scales(sim);
  res.mean_diameter = g.d;
  res.density_eff = g.rho_eff;
  res.inertial = prm.axial_rate * g.d * std::sqrt(g.rho_eff / prm.sigma3);
  const Real dt = sim.params().integ.dt;
  if (prm.verbose) announce(prm, res.inertial, dt);

  const StageEnd consolidated = consolidate_isotropic(sim, prm);
  res.consolidation_steps = consolidated.step;
  res.stages.push_back(consolidated.timing);

  const std::array<Real, 3> L0 = cell_lengths(sim);
  res.h0 = L0[2];
  res.V0 = cell_volume(sim);
  res.void_ratio0 = res.V0 / g.v_solid - 1;
  if (out) out->set_series_columns(kSeriesColumns);
  auto record = [&]() {
    res.series.push_back(measure_row(sim, prm, g, res.h0, res.V0, L0));
    if (out) out->append_series(series_row(res.series.back()));
  };
  SnapshotSchedule snapshots(prm, sim, out);
  record();
  snapshots.at(0);

  CellServo servo(prm, prm.max_lateral_rate);
  const bool lateral[3] = {true, true, false};
  const Real axial[3] = {0, 0, -prm.axial_rate};
  const long total = static_cast<long>(std::ceil(-std::log(1 - prm.target_strain) / (prm.axial_rate * dt)));
  Progress progress(prm.name + " shear", total);
  Real next_record = prm.record_strain;
  bool last = false;  // the step ends the test
  StageSteps stage;
  stage.last = std::numeric_limits<long>::max();  // until the target strain
  stage.before = [&](long) {
    const std::array<Real, 3> lengths = cell_lengths(sim);
    const std::array<Real, 3> target = lateral_targets(lengths, prm, L0);
    servo.update(sim, lateral, axial, target.data());
    const Real h = lengths[2];
    const Real eps_next = (res.h0 - h * (1 - prm.axial_rate * dt)) / res.h0;
    last = eps_next >= prm.target_strain;
    return StepPlan{false, last || eps_next >= next_record - 1e-12};  // a recorded step measures
  };
  stage.after = [&](long n, bool recorded) {
    if (recorded) {
      record();
      while (next_record <= res.series.back().eps_a + 1e-12) next_record += prm.record_strain;
      const PeriodicTriaxialRecord& r = res.series.back();
      if (prm.verbose) {
        char extra[160];
        std::snprintf(extra, sizeof extra, "eps_a %.2f%%, q %.1f kPa, eps_v %.2f%%, lateral %.1f/%.1f kPa",
                      100 * r.eps_a, 1e-3 * r.q, 100 * r.eps_v, 1e-3 * r.sigma2, 1e-3 * r.sigma3);
        progress.update(std::min(n, total), extra);
      }
      if (out && res.series.size() % 50 == 0) out->flush_series();
    }
    snapshots.at((res.h0 - cell_lengths(sim)[2]) / res.h0);
    return last;
  };
  res.stages.push_back(run_stage(sim, stage, nullptr).timing);
  res.stages.back().name = "shear";
  set_cell_rates(sim, Vec3());
  if (out) out->flush_series();

  finish_result(sim, res, progress, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  return res;
}

Real membrane_confinement(Real stiffness, Real eps) { return stiffness * std::max(eps, Real(0)); }

}  // namespace dem
