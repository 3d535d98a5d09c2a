#include "host/engine/simulation.hpp"
#include "host/engine/part_sampling.hpp"
#include "host/engine/cell_services.hpp"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <sstream>

#include "kernels/contact/contact_sums.hpp"
#include "kernels/neighbor/history_remap.hpp"
#include "kernels/core/reduce.hpp"
#include "host/util/sync_counts.hpp"

namespace dem {

namespace {

// The kernels of this file are free functions: nvcc allows no device lambda in a constructor or a private member.

/// Largest radius of the balls (m).
Real max_radius(const Particles& p) {
  auto r = p.radius;
  Real rmax = 0;
  Kokkos::parallel_reduce("dem::sim::rmax", RangePolicy(0, p.n),
      KOKKOS_LAMBDA(const int i, Real& acc) { acc = r(i) > acc ? r(i) : acc; }, Kokkos::Max<Real>(rmax));
  return rmax;
}

/// Moves each wall with a velocity by dt times it, as move_boundaries moves the host's copy.
void move_walls(const WallSet& walls, Real dt) {
  auto point = walls.point, velocity = walls.velocity;
  Kokkos::parallel_for("dem::sim::move_walls", RangePolicy(0, walls.n), KOKKOS_LAMBDA(const int w) {
    const Vec3 v = load(velocity, w);
    if (norm2(v) != 0) store(point, w, load(point, w) + dt * v);
  });
}

/// Moves the facet mesh's nodes by dt node_v; the largest node speed (m/s) goes to `speed`, in device memory.
void move_nodes(const FacetMesh& mesh, Real dt, Real* speed) {
  auto nx = mesh.node_x, nv = mesh.node_v;
  deterministic_reduce_to<0, 1>("dem::sim::move_mesh", mesh.nnode, KOKKOS_LAMBDA(const int k, Real* acc) {
    const Vec3 v = load(nv, k);
    store(nx, k, load(nx, k) + dt * v);
    acc[0] = norm(v);
  }, speed);
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
  // Copies of their own even where the device is the host: the host moves its copy as the device moves its own
  // (move_boundaries), so the two must not be one.
  hwall_point_ = Kokkos::create_mirror(HostSpace(), walls_.point);
  hwall_vel_ = Kokkos::create_mirror(HostSpace(), walls_.velocity);
  Kokkos::deep_copy(hwall_point_, walls_.point);
  Kokkos::deep_copy(hwall_vel_, walls_.velocity);
  rmax_ = max_radius(p_);
  cell_ = CellView("dem::sim::cell");
  servo_sums_ = CellServoSumsView("dem::sim::servo_sums");
  upload_cell();
  count_syncs();
  if (prm_.skin <= 0) throw std::invalid_argument("Verlet skin must be > 0");
  if (prm_.stats_every < 1 || prm_.stats_every > StepRows::kSlots)
    throw std::invalid_argument("stats_every must be in [1, " + std::to_string(StepRows::kSlots) + "]");
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
          const auto [kn, ks] = ContactLaws::max_stiffness(cp, r(i), 0, overlap_max * r(i));
          const Real krot = ks * r(i) * r(i) + ks * r(i) * r(i);  // shear lever + rolling spring (Rbar = R)
          const Real t = kc::min(kc::sqrt(m(i) / kn), kc::sqrt(in(i) / krot));
          acc = t < acc ? t : acc;
        }
      }, Kokkos::Min<Real>(dt));
  return dt * std::sqrt(prm_.integ.mass_scale);
}

void Simulation::rebuild() {
  const SyncScope part(SyncPart::kRebuild);
  read_cell();
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
        << ") m). Likely cause: "
        << (step_ == 0 ? "the state the run starts from puts it there (no step has moved it): a damaged specimen "
                         "cache or input; suggested fix: delete the cached specimen (.specimens) to build it again"
            : walls_.n == 0 && mesh_.ntri == 0
                ? "nothing bounds the domain on that side (no walls, no membrane); suggested fix: [box] walls = "
                  "true, or a box periodic along that axis"
                : "it passed through a wall or the membrane (a time step too large for the wall stiffness, or a "
                  "wall moving too fast); suggested fix: lower [solver] dt_safety or the wall speed, or stiffen "
                  "the wall material");
    throw BlowUp(msg.str());
  }
  bin_particles(p_, prm_.domain, 2 * rmax_ + prm_.skin, prm_.skin, cells_);
  integ_.renew(p_);
  const IndexView g2l = integ_.gid2local;
  balls_ = remap_history(detect_pairs(p_, cells_, {}, {}, &ball_bufs_), balls_, g2l, true, &ball_bufs_);
  FacetBins fb;
  if (mesh_.ntri > 0) fb = bin_facets(mesh_, cells_.grid, rmax_ + prm_.skin, facet_bins_);
  wall_c_ = remap_history(detect_wall_pairs(p_, walls_, mesh_, fb, cells_, prm_.skin, &wall_bufs_), wall_c_, g2l,
                          false, &wall_bufs_);
  index_contacts();
  Kokkos::deep_copy(p_.x_ref, p_.x);
  wall_disp_ = 0;
  fresh_ = false;
  ++times_.rebuilds;
}

void Simulation::index_contacts() {
  owner_ranges(p_, balls_, own_);
  build_adjacency(p_.n, balls_, balls_.j, adj_balls_);
  build_adjacency(p_.n, wall_c_, wall_c_.i, adj_walls_);
  object_offsets(wall_c_, walls_.n + mesh_.ntri, obj_offsets_);
}

namespace {

/// The step's part timers: on a timed step, each lap's seconds behind a fence, counted `weight` times; else nothing.
class PartClock {
 public:
  explicit PartClock(long weight) : weight_(static_cast<double>(weight)) {
    if (weight_ > 0) fenced_seconds();  // the device's work queued before is not the first lap's
  }
  void lap(double& into) {
    if (weight_ > 0) into += weight_ * fenced_seconds();
  }
  /// `part` timed whatever the weight, counted once: a rebuild, which waits for the device anyway.
  template <class F>
  void always(double& into, F&& part) {
    if (weight_ == 0) fenced_seconds();
    part();
    into += fenced_seconds();
  }

 private:
  double weight_;
  Kokkos::Timer t_;
  /// Seconds since the last reading, behind a fence.
  double fenced_seconds() {
    Kokkos::fence();
    count_fence();
    const double s = t_.seconds();
    t_.reset();
    return s;
  }
};

}  // namespace

void Simulation::step(bool measure) {
  PartClock clock(step_weight(step_, timed_until_));
  // The servo reads the state the last step left, as a servo on the host does before the step.
  if (servo_on_) {
    servo_step();
    clock.lap(times_.boundaries);
  }
  if (wall_servo_on_) {
    if (!fresh_) wall_loads_into(wall_c_, obj_offsets_, walls_.n, wall_load_);
    wall_servo_velocity(wall_servo_, wall_load_, fresh_, walls_.velocity, mesh_.node_v, prm_.integ.dt,
                        rows_.at(step_, StepRows::kWallSpeed));
    walls_stale_ = true;
    clock.lap(times_.boundaries);
  }
  if (rebuild_due()) clock.always(times_.rebuild, [this] { rebuild(); });
  const Real dt = prm_.integ.dt;
  prm_.integ.measure = measure;
  const SpecimenTable one = specimen();
  compute_ball_forces(p_, balls_, params_, one, rows_.overlap(step_, StepRows::kBalls));
  clock.lap(times_.forces);
  compute_wall_forces(p_, wall_c_, adj_walls_, walls_, mesh_, params_, dt, rows_.overlap(step_, StepRows::kWalls));
  clock.lap(times_.walls);
  if (membrane_.ntri > 0) {
    // Before integrate: the reactions are split at the closest points of the balls' current centres.
    membrane_prm_.dt = dt;
    membrane_forces(membrane_, cell_pressure_, FacetContacts{wall_c_, obj_offsets_, walls_.n, p_.x}, membrane_f_);
    membrane_integrate_to(membrane_, membrane_f_, membrane_prm_, rows_.at(step_, StepRows::kMembrane));
    clock.lap(times_.membrane);
  }
  integrate_to(p_, one, gather(), integ_, rows_.at(step_, StepRows::kLeapfrog));
  forces_current_ = false;
  clock.lap(times_.integrate);
  move_boundaries();
  clock.lap(times_.boundaries);
  time_ += dt;
  ++step_;
  if (measure || step_ - read_to_ >= prm_.stats_every) read_rows();
}

const Particles& Simulation::particles_with_forces() const {
  if (!forces_current_) {
    gather_forces(p_, gather());
    forces_current_ = true;
  }
  return p_;
}

void Simulation::move_boundaries() {
  const Real dt = prm_.integ.dt;
  Real vmax = 0;
  if (!wall_servo_on_) read_walls();  // a servo on the device that ended left the velocity it set
  for (int w = 0; w < walls_.n; ++w) {
    // The host does not know the velocity of the wall a servo on the device steers: its speed is read with the row.
    if (wall_servo_on_ && w == wall_servo_.wall) continue;
    const Vec3 v = load(hwall_vel_, w);
    if (norm2(v) == 0) continue;
    store(hwall_point_, w, load(hwall_point_, w) + dt * v);
    vmax = std::max(vmax, norm(v));
  }
  // The device moves its copy of the walls by the same arithmetic (no contraction, CMakeLists.txt): the host's
  // stays equal to it bit for bit, with no copy between them.
  if (vmax > 0 || wall_servo_on_) move_walls(walls_, dt);
  const Real wall_bound = wall_servo_on_ ? wall_servo_.servo.v_max : Real(-1);
  // Neighbours within the cut-off drift apart (or together) by at most |rate| dt times the cut-off.
  const Real reach = 2 * rmax_ + prm_.skin;
  Real cell_bound = -1;
  if (!servo_on_) read_cell();  // a servo on the device that ended left the rates it set
  if (servo_on_ || stretching(prm_.domain)) {
    // The device stretches its cell by the same arithmetic as the host its copy (no contraction, CMakeLists.txt).
    stretch_cell(p_, cell_, dt, reach, rows_.at(step_, StepRows::kCellSpeed));
    stretch_known_axes(prm_.domain, servo_on_ ? &servo_ : nullptr, dt);
    if (servo_on_) {
      // The servoed axes' speed is read with the row.
      cell_stale_ = true;
      cell_bound = servo_speed_bound(servo_, reach);
    } else {
      vmax = std::max(vmax, stretch_speed(prm_.domain, reach));
    }
  }
  // The membrane nodes' speed joins vmax when the row is read (read_rows).
  if (mesh_.ntri > 0) move_nodes(mesh_, dt, rows_.at(step_, StepRows::kNodeSpeed));
  boundary_step(vmax, dt, cell_bound, wall_bound);
}

void Simulation::set_membrane(const Membrane& m, const MembraneIntegrateParams& prm) {
  if (m.mesh.node_x.data() != mesh_.node_x.data() || m.ntri != mesh_.ntri)
    throw std::invalid_argument("set_membrane: the membrane's mesh is not this simulation's facet mesh");
  membrane_ = m;
  membrane_prm_ = prm;
  membrane_f_ = Vec3View("dem::sim::membrane_force", m.nnode);  // here, not in a step
  membrane_prm_.move_nodes = false;  // move_boundaries moves every facet node by dt node_v
}

namespace {
/// N sums of a cell's contact terms (OwnerSums), each over `volume`: the Love-Weber sums of the ball-ball contacts,
/// all nine components (N = 9, row-major) or the diagonal alone (N = 3), each component summed in the same order
/// either way, so with the same bits; the servo's stiffness.
template <int N, class Terms>
std::array<Real, N> per_volume(const char* label, const Simulation& sim, const Terms& terms, Real volume) {
  Real s[N];
  sim.owner_sums(label, terms, s);
  std::array<Real, N> out;
  for (int q = 0; q < N; ++q) out[q] = s[q] / volume;
  return out;
}
}  // namespace

// The image is worked out once per launch, as the pair loops do.
std::array<Real, 9> Simulation::contact_stress(Real volume) const {
  return per_volume<9>("dem::sim::contact_stress", *this,
                       LoveWeberTerms<9, OneImage>{p_.x, OneImage{MinImage(domain())}}, volume);
}

std::array<Real, 3> Simulation::contact_stress_diagonal(Real volume) const {
  return per_volume<3>("dem::sim::contact_stress_diagonal", *this,
                       LoveWeberTerms<3, OneImage>{p_.x, OneImage{MinImage(domain())}}, volume);
}

std::array<Real, 3> Simulation::cell_stiffness() const {
  const Domain dom = domain();
  return per_volume<3>("dem::sim::cell_stiffness", *this,
                       StiffnessTerms<OneImage>{p_.x, p_.radius, OneImage{MinImage(dom)}}, dom.volume());
}

Simulation::WallLoads Simulation::wall_loads(bool facets) const {
  const int nobj = walls_.n + (facets ? mesh_.ntri : 0);
  WallLoads out{std::vector<Vec3>(static_cast<std::size_t>(nobj)), std::vector<int>(static_cast<std::size_t>(nobj), 0)};
  if (fresh_ || nobj == 0) return out;
  wall_loads_into(wall_c_, obj_offsets_, nobj, wall_load_);
  if (hwall_load_.extent(0) != wall_load_.extent(0)) hwall_load_ = Kokkos::create_mirror(HostSpace(), wall_load_);
  const auto first = std::make_pair(0, nobj);
  Kokkos::deep_copy(Kokkos::subview(hwall_load_, first), Kokkos::subview(wall_load_, first));
  for (int k = 0; k < nobj; ++k) {
    const WallLoad& w = hwall_load_(k);
    out.force[static_cast<std::size_t>(k)] = Vec3(w.force[0], w.force[1], w.force[2]);
    out.touching[static_cast<std::size_t>(k)] = w.touching;
  }
  return out;
}

Real Simulation::unbalanced_ratio() const {
  if (p_.n == 0) return 0;
  Real s[2];
  owner_sums("dem::sim::contact_force_sum", ForceTerms(), s);
  return dem::unbalanced_ratio(stats().unbalanced, p_.n, s[0], s[1]);
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
