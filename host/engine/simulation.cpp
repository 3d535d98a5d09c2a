#include "host/engine/simulation.hpp"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <sstream>

#include "kernels/neighbor/history_remap.hpp"
#include "kernels/core/reduce.hpp"

namespace dem {

namespace {
double seconds_since(Kokkos::Timer& t) {
  Kokkos::fence();
  const double s = t.seconds();
  t.reset();
  return s;
}

// The kernels of this file are free functions: nvcc allows no device lambda in a constructor or a private member.

/// Largest radius of the balls (m).
Real max_radius(const Particles& p) {
  auto r = p.radius;
  Real rmax = 0;
  Kokkos::parallel_reduce("dem::sim::rmax", RangePolicy(0, p.n),
      KOKKOS_LAMBDA(const int i, Real& acc) { acc = r(i) > acc ? r(i) : acc; }, Kokkos::Max<Real>(rmax));
  return rmax;
}

/// The periodic cell's affine step: positions, and the positions of the last rebuild, stretched by s about lo.
void stretch_about(const Particles& p, const Real (&lo)[3], const Real (&s)[3]) {
  auto x = p.x, xr = p.x_ref;
  const Real l0 = lo[0], l1 = lo[1], l2 = lo[2], s0 = s[0], s1 = s[1], s2 = s[2];
  Kokkos::parallel_for("dem::sim::affine", RangePolicy(0, p.n), KOKKOS_LAMBDA(const int i) {
    const Real l[3] = {l0, l1, l2}, f[3] = {s0, s1, s2};
    for (int d = 0; d < 3; ++d) {
      x(i, d) = l[d] + (x(i, d) - l[d]) * f[d];
      xr(i, d) = l[d] + (xr(i, d) - l[d]) * f[d];
    }
  });
}

/// Moves the facet mesh's nodes by dt node_v; returns the largest node speed (m/s).
Real move_nodes(const FacetMesh& mesh, Real dt) {
  auto nx = mesh.node_x, nv = mesh.node_v;
  Real nmax = 0;
  Kokkos::parallel_reduce("dem::sim::move_mesh", RangePolicy(0, mesh.nnode),
      KOKKOS_LAMBDA(const int k, Real& acc) {
        const Vec3 v = load(nv, k);
        store(nx, k, load(nx, k) + dt * v);
        acc = norm(v) > acc ? norm(v) : acc;
      }, Kokkos::Max<Real>(nmax));
  return nmax;
}

}  // namespace

Simulation::Simulation(Particles particles, WallSet walls, FacetMesh mesh, const std::vector<ContactParams>& table,
                       int nmat, SimParams prm)
    : p_(std::move(particles)), walls_(std::move(walls)), mesh_(std::move(mesh)), prm_(prm) {
  if (static_cast<int>(table.size()) != nmat * nmat)
    throw std::invalid_argument("contact parameter table must have nmat^2 entries");
  params_ = ParamTableView("dem::sim::params", nmat, nmat);
  set_contact_params(table);
  if (walls_.n == 0) walls_ = WallSet(0);
  hwall_point_ = Kokkos::create_mirror_view_and_copy(HostSpace(), walls_.point);
  hwall_vel_ = Kokkos::create_mirror_view_and_copy(HostSpace(), walls_.velocity);
  rmax_ = max_radius(p_);
  if (prm_.skin <= 0) throw std::invalid_argument("Verlet skin must be > 0");
}

void Simulation::set_contact_params(const std::vector<ContactParams>& table) {
  const int nmat = static_cast<int>(params_.extent(0));
  if (static_cast<int>(table.size()) != nmat * nmat)
    throw std::invalid_argument("contact parameter table must have nmat^2 entries");
  auto hp = Kokkos::create_mirror_view(params_);
  for (int a = 0; a < nmat; ++a)
    for (int b = 0; b < nmat; ++b) hp(a, b) = table[a * nmat + b];
  Kokkos::deep_copy(params_, hp);
}

Real Simulation::critical_dt() const {
  auto m = p_.mass, in = p_.inertia, r = p_.radius;
  auto mat = p_.material;
  auto params = params_;
  const Real overlap_max = prm_.overlap_limit;
  Real dt = 0;
  Kokkos::parallel_reduce("dem::sim::critical_dt", RangePolicy(0, p_.n),
      KOKKOS_LAMBDA(const int i, Real& acc) {
        for (int b = 0; b < static_cast<int>(params.extent(1)); ++b) {
          const ContactParams& cp = params(mat(i), b);
          // Ball-wall is the stiffest contact; a Hertzian one stiffens up to the overlap guard.
          const Real kn = NormalElastic::max_stiffness(cp, r(i), 0, overlap_max * r(i));
          const Real ks = kn / cp.kratio;
          const Real krot = ks * r(i) * r(i) + ks * r(i) * r(i);  // shear lever + rolling spring (Rbar = R)
          const Real t = kc::min(kc::sqrt(m(i) / kn), kc::sqrt(in(i) / krot));
          acc = t < acc ? t : acc;
        }
      }, Kokkos::Min<Real>(dt));
  return dt * std::sqrt(prm_.integ.mass_scale);
}

bool Simulation::rebuild_due() const {
  if (fresh_) return true;
  const Real d = std::sqrt(stats_.max_disp2);
  return 2 * d > prm_.skin || d + wall_disp_ > prm_.skin;
}

void Simulation::rebuild() {
  // Balls move less than the skin between rebuilds, so an escape is caught within a rebuild of happening.
  const int out = ball_outside(p_, prm_.domain, 2);
  if (out >= 0) {
    auto hx = Kokkos::create_mirror_view_and_copy(HostSpace(), p_.x);
    auto hg = Kokkos::create_mirror_view_and_copy(HostSpace(), p_.gid);
    const Domain& d = prm_.domain;
    std::ostringstream msg;
    msg << "blow-up at step " << step_ << ": particle " << hg(out) << " left the domain (centre at (" << hx(out, 0)
        << ", " << hx(out, 1) << ", " << hx(out, 2) << ") m, domain (" << d.lo[0] << ", " << d.lo[1] << ", "
        << d.lo[2] << ") to (" << d.hi[0] << ", " << d.hi[1] << ", " << d.hi[2]
        << ") m). Likely cause: it passed through a wall or the membrane (a time step too large for the wall "
           "stiffness, or a wall moving too fast); suggested fix: lower [solver] dt_safety or the wall speed, "
           "or stiffen the wall material";
    throw BlowUp(msg.str());
  }
  bin_particles(p_, prm_.domain, 2 * rmax_ + prm_.skin, cells_);
  const IndexView g2l = gid_to_local(p_);
  balls_ = remap_history(detect_pairs(p_, prm_.domain, cells_, prm_.skin), balls_, g2l, true);
  FacetBins fb;
  if (mesh_.ntri > 0) fb = bin_facets(mesh_, cells_.grid, rmax_ + prm_.skin);
  wall_c_ = remap_history(detect_wall_pairs(p_, walls_, mesh_, fb, cells_, prm_.skin), wall_c_, g2l, false);
  index_contacts();
  Kokkos::deep_copy(p_.x_ref, p_.x);
  wall_disp_ = 0;
  fresh_ = false;
  ++times_.rebuilds;
}

void Simulation::index_contacts() {
  own_ = owner_ranges(p_, balls_);
  adj_balls_ = build_adjacency(p_.n, balls_, balls_.j);
  adj_walls_ = build_adjacency(p_.n, wall_c_, wall_c_.i);
  obj_offsets_ = object_offsets(wall_c_, walls_.n + mesh_.ntri);
}

void Simulation::step(bool measure) {
  Kokkos::Timer t;
  if (rebuild_due()) rebuild();
  times_.rebuild += seconds_since(t);
  const Real dt = prm_.integ.dt;
  const OverlapStat ob = compute_ball_forces(p_, balls_, params_, prm_.domain, dt);
  times_.forces += seconds_since(t);
  const OverlapStat ow = compute_wall_forces(p_, wall_c_, adj_walls_, walls_, mesh_, params_, dt);
  times_.walls += seconds_since(t);
  check_blowup(ob, ow);
  if (membrane_.ntri > 0) {
    // Before integrate: the reactions are split at the closest points of the balls' current centres.
    membrane_prm_.dt = dt;
    membrane_forces(membrane_, cell_pressure_, FacetContacts{wall_c_, obj_offsets_, walls_.n, p_.x}, membrane_f_);
    membrane_stats_ = membrane_integrate(membrane_, membrane_f_, membrane_prm_);
    times_.membrane += seconds_since(t);
  }
  prm_.integ.measure = measure;
  stats_ = integrate(p_, prm_.integ, make_gather(balls_, own_, adj_balls_, wall_c_, adj_walls_));
  times_.integrate += seconds_since(t);
  if (stats_.bad >= 0 || stats_.max_move2 > prm_.overlap_limit * prm_.overlap_limit) check_blowup(ob, ow);
  move_boundaries();
  times_.boundaries += seconds_since(t);
  time_ += dt;
  ++step_;
}

void Simulation::move_boundaries() {
  const Real dt = prm_.integ.dt;
  Real vmax = 0;
  for (int w = 0; w < walls_.n; ++w) {
    const Vec3 v = load(hwall_vel_, w);
    if (norm2(v) == 0) continue;
    store(hwall_point_, w, load(hwall_point_, w) + dt * v);
    vmax = std::max(vmax, norm(v));
  }
  if (vmax > 0) Kokkos::deep_copy(walls_.point, hwall_point_);
  const Real* rate = prm_.domain.strain_rate;
  if (rate[0] != 0 || rate[1] != 0 || rate[2] != 0) {
    Domain& dom = prm_.domain;
    const Real s[3] = {1 + rate[0] * dt, 1 + rate[1] * dt, 1 + rate[2] * dt};
    const Real lo[3] = {dom.lo[0], dom.lo[1], dom.lo[2]};
    stretch_about(p_, lo, s);
    for (int d = 0; d < 3; ++d) dom.hi[d] = lo[d] + (dom.hi[d] - lo[d]) * s[d];
    // Neighbours within the cut-off drift apart (or together) by at most |rate| dt times the cut-off.
    const Real rate_max = std::max({std::fabs(rate[0]), std::fabs(rate[1]), std::fabs(rate[2])});
    vmax = std::max(vmax, rate_max * (2 * rmax_ + prm_.skin));
  }
  if (mesh_.ntri > 0) vmax = std::max(vmax, move_nodes(mesh_, dt));
  wall_disp_ += vmax * dt;
}

void Simulation::check_blowup(const OverlapStat& ob, const OverlapStat& ow) const {
  std::ostringstream msg;
  auto gid_of = [&](const ContactList& c, int k) {
    auto hi = Kokkos::create_mirror_view_and_copy(HostSpace(), Kokkos::subview(c.i, std::make_pair(k, k + 1)));
    auto hg = Kokkos::create_mirror_view_and_copy(HostSpace(), Kokkos::subview(p_.gid, std::make_pair(hi(0), hi(0) + 1)));
    return hg(0);
  };
  if (stats_.bad >= 0) {
    auto hg = Kokkos::create_mirror_view_and_copy(HostSpace(), p_.gid);
    msg << "blow-up at step " << step_ << ": particle " << hg(stats_.bad)
        << " has a non-finite position. Likely cause: time step above the critical one or a servo gain too high; "
           "suggested fix: lower [solver] dt_safety (now dt = "
        << prm_.integ.dt << " s, critical " << critical_dt() << " s)";
    throw BlowUp(msg.str());
  }
  if (stats_.max_move2 > prm_.overlap_limit * prm_.overlap_limit) {
    // A ball that moves this far in one step would overlap anything it meets by more than the overlap limit.
    auto hv = Kokkos::create_mirror_view_and_copy(HostSpace(), p_.v);
    auto hr = Kokkos::create_mirror_view_and_copy(HostSpace(), p_.radius);
    auto hg = Kokkos::create_mirror_view_and_copy(HostSpace(), p_.gid);
    int fast = 0;
    Real worst_move = -1;
    for (int i = 0; i < p_.n; ++i) {
      const Real move = norm(load(hv, i)) * prm_.integ.dt / hr(i);
      if (move > worst_move) worst_move = move, fast = i;
    }
    msg << "blow-up at step " << step_ << ": particle " << hg(fast) << " moved " << worst_move * 100
        << "% of its radius in one step (limit " << prm_.overlap_limit * 100
        << "%, the overlap limit): its kinetic energy jumped beyond what the loads can give. Likely cause: a time "
           "step above the critical one for the stiffness reached, or a servo gain or wall speed too high; "
           "suggested fix: lower [solver] dt_safety (now dt = "
        << prm_.integ.dt << " s, critical " << critical_dt() << " s) or the servo gain";
    throw BlowUp(msg.str());
  }
  const OverlapStat& worst = ob.ratio >= ow.ratio ? ob : ow;
  if (worst.ratio > prm_.overlap_limit) {
    const bool wall = ow.ratio > ob.ratio;
    msg << "blow-up at step " << step_ << ": particle " << gid_of(wall ? wall_c_ : balls_, worst.contact)
        << " overlaps " << (wall ? "a wall" : "another particle") << " by " << worst.ratio * 100
        << "% of its radius (limit " << prm_.overlap_limit * 100
        << "%). Likely cause: stiffness too low for the load, a wall or servo moving too fast, or too large a time "
           "step; suggested fix: raise emod, lower the wall speed or servo gain, or lower [solver] dt_safety";
    throw BlowUp(msg.str());
  }
}

void Simulation::set_membrane(const Membrane& m, const MembraneIntegrateParams& prm) {
  if (m.mesh.node_x.data() != mesh_.node_x.data() || m.ntri != mesh_.ntri)
    throw std::invalid_argument("set_membrane: the membrane's mesh is not this simulation's facet mesh");
  membrane_ = m;
  membrane_prm_ = prm;
  membrane_prm_.move_nodes = false;  // move_boundaries moves every facet node by dt node_v
}

void Simulation::set_strain_rate(const Vec3& rate) {
  prm_.domain.strain_rate[0] = rate.x;
  prm_.domain.strain_rate[1] = rate.y;
  prm_.domain.strain_rate[2] = rate.z;
}

namespace {
/// The Love-Weber sums of the ball-ball contacts over `volume`: all nine components (N = 9, row-major) or the
/// diagonal alone (N = 3). Each component is summed in the same order either way, so it has the same bits.
template <int N>
std::array<Real, N> love_weber_stress(const char* label, const ContactList& c, const Vec3View& x, const Domain& dom,
                                      Real volume) {
  static_assert(N == 9 || N == 3, "the whole tensor or its diagonal");
  Real s[N];
  const MinImage image(dom);  // worked out once per launch, as the pair loops do
  deterministic_reduce<N, 0>(label, c.n, KOKKOS_LAMBDA(const int k, Real* v) {
    const Vec3 f = load(c.fc, k);
    const Vec3 l = image(load(x, c.j(k)) - load(x, c.i(k)));
    for (int q = 0; q < N; ++q) v[q] = -f[N == 9 ? q / 3 : q] * l[N == 9 ? q % 3 : q];
  }, s);
  std::array<Real, N> out;
  for (int q = 0; q < N; ++q) out[q] = s[q] / volume;
  return out;
}
}  // namespace

std::array<Real, 9> Simulation::contact_stress(Real volume) const {
  return love_weber_stress<9>("dem::sim::contact_stress", balls_, p_.x, prm_.domain, volume);
}

std::array<Real, 3> Simulation::contact_stress_diagonal(Real volume) const {
  return love_weber_stress<3>("dem::sim::contact_stress_diagonal", balls_, p_.x, prm_.domain, volume);
}

void Simulation::set_wall_velocity(int w, const Vec3& v) {
  store(hwall_vel_, w, v);
  Kokkos::deep_copy(walls_.velocity, hwall_vel_);
}

void Simulation::set_wall_velocities(const std::vector<Vec3>& v) {
  if (static_cast<int>(v.size()) != walls_.n)
    throw std::invalid_argument("set_wall_velocities: " + std::to_string(v.size()) + " velocities for " +
                                std::to_string(walls_.n) + " walls");
  for (int w = 0; w < walls_.n; ++w) store(hwall_vel_, w, v[static_cast<std::size_t>(w)]);
  Kokkos::deep_copy(walls_.velocity, hwall_vel_);
}

Vec3 Simulation::wall_velocity(int w) const { return load(hwall_vel_, w); }

Vec3 Simulation::wall_point(int w) const { return load(hwall_point_, w); }

void Simulation::set_wall_point(int w, const Vec3& p) {
  const Real moved = norm(p - load(hwall_point_, w));
  store(hwall_point_, w, p);
  Kokkos::deep_copy(walls_.point, hwall_point_);
  wall_disp_ += moved;
}

std::vector<Vec3> Simulation::wall_forces() {
  if (fresh_) return std::vector<Vec3>(walls_.n + mesh_.ntri);
  wall_forces_into(wall_c_, obj_offsets_, wall_force_);
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), wall_force_);
  std::vector<Vec3> out(h.extent(0));
  for (std::size_t k = 0; k < out.size(); ++k) out[k] = load(h, static_cast<int>(k));
  return out;
}

std::vector<int> Simulation::wall_contact_counts() const {
  const int nobj = walls_.n + mesh_.ntri;
  if (fresh_) return std::vector<int>(nobj, 0);
  IndexView counts("dem::sim::wall_contact_counts", nobj);
  auto off = obj_offsets_;
  auto fn = wall_c_.fn;
  Kokkos::parallel_for("dem::sim::wall_contact_counts", RangePolicy(0, nobj), KOKKOS_LAMBDA(const int o) {
    int c = 0;
    for (int k = off(o); k < off(o + 1); ++k) c += fn(k) > 0 ? 1 : 0;
    counts(o) = c;
  });
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), counts);
  return std::vector<int>(h.data(), h.data() + nobj);
}

Real Simulation::unbalanced_ratio() const {
  if (p_.n == 0) return 0;
  Real s[2];
  const ContactList b = balls_, w = wall_c_;
  const int nb = b.n;
  deterministic_reduce<2, 0>("dem::sim::contact_force_sum", b.n + w.n, KOKKOS_LAMBDA(const int k, Real* v) {
    const Vec3 f = k < nb ? load(b.fc, k) : load(w.fc, k - nb);
    const Real fn = k < nb ? b.fn(k) : w.fn(k - nb);
    v[0] = norm(f);
    v[1] = fn > 0 ? Real(1) : Real(0);
  }, s);
  if (s[1] == 0) return 1;
  return (stats_.unbalanced / p_.n) / (s[0] / s[1]);
}

std::array<long, 2> Simulation::touching() const {
  std::array<long, 2> out{};
  const ContactList* lists[2] = {&balls_, &wall_c_};
  for (int q = 0; q < 2; ++q) {
    auto fn = lists[q]->fn;
    long c = 0;
    Kokkos::parallel_reduce("dem::sim::touching", RangePolicy(0, lists[q]->n),
        KOKKOS_LAMBDA(const int k, long& acc) { acc += fn(k) > 0 ? 1 : 0; }, c);
    out[q] = c;
  }
  return out;
}

std::string describe(const StageTimes& t, long particles, long steps) {
  char line[400];
  // A membrane's share only where there is one; "boundaries": moving walls, membrane nodes or the periodic
  // cell's stretch. A GPU's thread count says nothing a user can set.
  char membrane[48] = "";
  if (t.membrane > 0) std::snprintf(membrane, sizeof membrane, "membrane %.1f s, ", t.membrane);
  char threads[32] = "";
  if (Kokkos::SpaceAccessibility<HostSpace, MemSpace>::accessible)
    std::snprintf(threads, sizeof threads, " (%d threads)", ExecSpace().concurrency());
  char walls[48] = "";
  if (t.walls > 0) std::snprintf(walls, sizeof walls, "ball-wall %.1f s, ", t.walls);
  std::snprintf(line, sizeof line,
                "%ld steps, rebuild %.1f s (%ld rebuilds), ball-ball %.1f s, %s%sgather+integrate %.1f s, "
                "boundaries %.1f s; %.3g particle-steps/s on %s%s",
                steps, t.rebuild, t.rebuilds, t.forces, walls, membrane, t.integrate, t.boundaries,
                particles * static_cast<double>(steps) / std::max(1e-9, t.loop()), ExecSpace::name(), threads);
  return line;
}

}  // namespace dem
