#include "host/engine/cell_batch.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "host/engine/builder.hpp"
#include "host/engine/cell_services.hpp"
#include "kernels/contact/contact_sums.hpp"
#include "kernels/core/buffers.hpp"
#include "kernels/neighbor/history_remap.hpp"

namespace dem {

namespace {

// The kernels of this file are free functions: nvcc allows no device lambda in a constructor or a private member.

/// Specimen s's particles copied into the batch's at `first`, its gids moved up by `first` (unique in the batch, in
/// the same order as alone: each specimen's contact keys sort as its own), tagged with s.
void place_specimen(const Particles& from, Particles& to, int first, int s) {
  const auto range = std::make_pair(first, first + from.n);
  const auto all = Kokkos::ALL;
  Kokkos::deep_copy(Kokkos::subview(to.x, range, all), from.x);
  Kokkos::deep_copy(Kokkos::subview(to.v, range, all), from.v);
  Kokkos::deep_copy(Kokkos::subview(to.w, range, all), from.w);
  Kokkos::deep_copy(Kokkos::subview(to.x_ref, range, all), from.x_ref);
  Kokkos::deep_copy(Kokkos::subview(to.radius, range), from.radius);
  Kokkos::deep_copy(Kokkos::subview(to.mass, range), from.mass);
  Kokkos::deep_copy(Kokkos::subview(to.inertia, range), from.inertia);
  Kokkos::deep_copy(Kokkos::subview(to.material, range), from.material);
  auto gid = to.gid;
  auto spec = to.specimen;
  auto g0 = from.gid;
  Kokkos::parallel_for("dem::batch::place", RangePolicy(0, from.n), KOKKOS_LAMBDA(const int i) {
    gid(first + i) = g0(i) + static_cast<std::uint32_t>(first);
    spec(first + i) = s;
  });
}

/// Positions at the last rebuild: the rebuilt specimens' set to their positions now.
void mark_rebuilt(const Particles& p, const SpecimenCellsView& cells) {
  auto x = p.x, xr = p.x_ref;
  auto owner = p.specimen;
  Kokkos::parallel_for("dem::batch::x_ref", RangePolicy(0, p.n), KOKKOS_LAMBDA(const int i) {
    if (!cells(owner(i)).rebuild) return;
    for (int d = 0; d < 3; ++d) xr(i, d) = x(i, d);
  });
}

/// Each specimen's first contact in the key-sorted list: its first gid's keys start there (S + 1 entries).
IndexView contact_starts(const ContactList& c, const SpecimenParamsView& spec, int count) {
  IndexView first("dem::batch::contact_first", count + 1);
  auto key = c.key;
  const int n = c.n;
  Kokkos::parallel_for("dem::batch::contact_first", RangePolicy(0, count + 1), KOKKOS_LAMBDA(const int s) {
    first(s) = s < count ? key_lower_bound(key, n, std::uint64_t(spec(s).first) << 32) : n;
  });
  return first;
}

/// A batch row: a specimen's Leapfrog values, then its cell's stretch speed (m/s) where its servo is on the device.
constexpr int kSpeedColumn = Leapfrog::kValues;
constexpr int kRowWidth = kSpeedColumn + 1;

}  // namespace

CellBatch::CellBatch(const std::vector<const Simulation*>& specimens) {
  if (specimens.empty()) throw std::invalid_argument("cell batch: no specimen");
  int total = 0;
  for (std::size_t s = 0; s < specimens.size(); ++s) {
    const Simulation& sim = *specimens[s];
    const auto bad = [&](const std::string& why) {
      throw std::invalid_argument("cell batch: specimen " + std::to_string(s) + ": " + why);
    };
    const Domain& dom = sim.domain();
    if (!(dom.periodic[0] && dom.periodic[1] && dom.periodic[2])) bad("its cell is not periodic along x, y and z");
    if (sim.num_walls() > 0 || sim.mesh().ntri > 0) bad("it has walls or facets");
    if (sim.step_count() > 0) bad("it has taken steps already; a batch starts from specimens not yet stepped");
    if (!(sim.params().integ.dt > 0)) bad("its time step is not set");
    // Its gids, moved up by its first particle, are its items of the trees of its sums (particle_tree_, owner_tree_).
    if (sim.particles().gid_bound() != static_cast<std::uint32_t>(sim.particles().n))
      bad("its ball ids are not 0 to n - 1");
    const int nmat = static_cast<int>(sim.contact_table().extent(0));
    if (s == 0) nmat_ = nmat;
    if (nmat != nmat_)
      bad("it has " + std::to_string(nmat) + " materials and specimen 0 has " + std::to_string(nmat_) +
          ": the batch's material-pair table has the same rows for each");
    Specimen sp;
    sp.prm = sim.params();
    sp.critical_dt = sim.critical_dt();
    sp.first = total;
    sp.count = sim.particles().n;
    total += sp.count;
    spec_.push_back(sp);
  }
  p_ = Particles(total);
  std::vector<std::pair<int, int>> gids;  // every specimen's, stopped or not: a stopped one's stress is its state's
  for (const Specimen& sp : spec_) gids.emplace_back(sp.first, sp.first + sp.count);
  owner_tree_.plan(gids);
  params_ = ParamTableView("dem::batch::params", spec_.size() * nmat_, nmat_);
  for (std::size_t s = 0; s < specimens.size(); ++s) {
    const Simulation& sim = *specimens[s];
    Specimen& sp = spec_[s];
    place_specimen(sim.particles(), p_, sp.first, static_cast<int>(s));
    const int row = static_cast<int>(s) * nmat_;
    Kokkos::deep_copy(Kokkos::subview(params_, std::make_pair(row, row + nmat_), Kokkos::ALL), sim.contact_table());
    auto r = Kokkos::create_mirror_view_and_copy(HostSpace(), sim.particles().radius);
    for (int i = 0; i < sp.count; ++i) sp.rmax = std::max(sp.rmax, r(i));
  }
  dev_spec_ = SpecimenParamsView("dem::batch::specimens", spec_.size());
  host_spec_ = Kokkos::create_mirror_view(dev_spec_);
  rows_ = StepRowsView("dem::batch::rows", spec_.size(), kRowWidth);
  host_rows_ = Kokkos::create_mirror_view(rows_);
  worst_ = Kokkos::View<OverlapStat, MemSpace>("dem::batch::worst");
  items_.exceeded_count = Kokkos::View<int, MemSpace>("dem::batch::exceeded_count");
  stretching_ = Kokkos::View<char*, MemSpace>("dem::batch::stretching", spec_.size());
  sums_ = Kokkos::View<Real**, Kokkos::LayoutRight, MemSpace>("dem::batch::sums", spec_.size(), 3);
  host_sums_ = Kokkos::create_mirror_view(sums_);
  host_stretching_ = Kokkos::create_mirror_view(stretching_);
  servo_slots_ = CellServoSlotView("dem::batch::servo_slots", spec_.size());
  host_slots_ = Kokkos::create_mirror_view(servo_slots_);
  servo_sums_ = CellServoSumRowsView("dem::batch::servo_sums", spec_.size());
  walls_ = ContactList(0);
  adj_walls_ = build_adjacency(p_.n, walls_, walls_.i);
}

int CellBatch::running_count() const {
  int n = 0;
  for (const Specimen& sp : spec_) n += sp.running ? 1 : 0;
  return n;
}

void CellBatch::set_strain_rate(int s, const Vec3& rate) {
  Specimen& sp = spec_.at(static_cast<std::size_t>(s));
  read_cells();
  if (sp.servo.on) {
    sp.servo.on = 0;
    upload_slots();
  }
  Domain& dom = sp.prm.domain;
  dirty_ = dirty_ || dom.strain_rate[0] != rate.x || dom.strain_rate[1] != rate.y || dom.strain_rate[2] != rate.z;
  dom.strain_rate[0] = rate.x;
  dom.strain_rate[1] = rate.y;
  dom.strain_rate[2] = rate.z;
}

void CellBatch::stop(int s) {
  Specimen& sp = spec_.at(static_cast<std::size_t>(s));
  if (!sp.running) return;
  sp.running = false;
  if (sp.servo.on) {
    sp.servo.on = 0;
    upload_slots();
  }
  if (!fresh_) plan();
}

void CellBatch::upload() const {
  if (!dirty_) return;
  dirty_ = false;
  read_cells();  // the cells the device's servos changed are the device's
  for (std::size_t s = 0; s < spec_.size(); ++s) {
    const Specimen& sp = spec_[s];
    SpecimenParams& h = host_spec_(s);
    h.dom = sp.prm.domain;
    h.integ = sp.prm.integ;
    h.first = sp.first;
    h.count = sp.count;
    h.material_row = static_cast<int>(s) * nmat_;
    h.overlap_limit = sp.prm.overlap_limit;
  }
  Kokkos::deep_copy(dev_spec_, host_spec_);
}

void CellBatch::rebuild() {
  read_cells();
  std::vector<SpecimenBin> bins;
  for (const Specimen& sp : spec_)
    bins.push_back({sp.first, sp.count, sp.prm.domain, 2 * sp.rmax + sp.prm.skin, sp.prm.skin, sp.running});
  bin_specimens(p_, bins, cells_);
  integ_.renew(p_);
  balls_ = remap_history(detect_pairs(p_, cells_, balls_.key, own_, &ball_bufs_), balls_, integ_.gid2local, true,
                         &ball_bufs_);
  owner_ranges(p_, balls_, own_);
  build_adjacency(p_.n, balls_, balls_.j, adj_balls_);
  mark_rebuilt(p_, cells_.specimens);
  for (Specimen& sp : spec_) {
    if (!sp.running) continue;
    sp.wall_disp = 0;
    ++sp.rebuilds;
  }
  const IndexView first = contact_starts(balls_, dev_spec_, size());
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), first);
  contact_first_.assign(h.data(), h.data() + h.extent(0));
  fresh_ = false;
  ++rebuild_steps_;
  plan();
}

void CellBatch::plan() {
  std::vector<std::pair<int, int>> particles;
  std::vector<int> item_first(spec_.size() + 1, 0);
  for (std::size_t s = 0; s < spec_.size(); ++s) {
    const Specimen& sp = spec_[s];
    const int c0 = contact_first_[s], c1 = contact_first_[s + 1];
    // A stopped specimen has no items: nothing of it is computed or moved.
    particles.emplace_back(sp.first, sp.running ? sp.first + sp.count : sp.first);
    const int items = sp.running ? (c1 - c0 + kContactLanes - 1) / kContactLanes : 0;
    item_first[s + 1] = item_first[s] + items;
  }
  particle_tree_.plan(particles);
  items_.specimens = size();
  items_.items = item_first.back();
  items_.exceeded = room(exceeded_buf_, static_cast<std::size_t>(contact_first_.back()), "dem::batch::exceeded");
  items_.contact_first = IndexView("dem::batch::contact_first", contact_first_.size());
  items_.item_first = IndexView("dem::batch::item_first", item_first.size());
  Kokkos::deep_copy(items_.contact_first,
                    Kokkos::View<const int*, HostSpace, Kokkos::MemoryUnmanaged>(contact_first_.data(), contact_first_.size()));
  Kokkos::deep_copy(items_.item_first,
                    Kokkos::View<const int*, HostSpace, Kokkos::MemoryUnmanaged>(item_first.data(), item_first.size()));
}

void CellBatch::step(const std::vector<char>& measure) {
  bool measured = false;  // some specimen's step is
  for (std::size_t s = 0; s < spec_.size(); ++s) {
    const bool m = measure.empty() || measure[s];
    dirty_ = dirty_ || spec_[s].prm.integ.measure != m;
    spec_[s].prm.integ.measure = m;
    measured = measured || m;
  }
  upload();
  servo_step();
  // A specimen's lists expire as its Simulation's would (lists_expired, read every step). A rebuild changes no bit
  // of a run (contact_sums.hpp, step_wrap), so every running specimen is rebuilt when one is due: their lists then
  // expire together, at the pace of the fastest, where each on its own would have the batch rebuild at most steps.
  bool any = fresh_;
  for (const Specimen& sp : spec_)
    any = any || (sp.running && lists_expired(sp.stats.max_disp2, sp.wall_disp, sp.prm.skin));
  if (any) rebuild();
  compute_ball_forces(p_, balls_, params_, dev_spec_, items_, OverlapResultView(worst_.data()));
  integrate_batch_to(p_, dev_spec_, particle_tree_, make_gather(balls_, own_, adj_balls_, walls_, adj_walls_), integ_,
                     rows_.data(), kRowWidth, measured);
  // The cells' stretch, on the device and on the host alike (Simulation::move_boundaries): the host's copy of a
  // servoed cell moves along the axes whose rate it knows, and the speed of its stretch comes with its row.
  auto& hon = host_stretching_;
  bool stretch = false, changed = !stretching_sent_;
  std::vector<Real>& speed = speed_;
  speed.assign(spec_.size(), 0);
  for (std::size_t s = 0; s < spec_.size(); ++s) {
    Specimen& sp = spec_[s];
    const bool servoed = sp.running && sp.servo.on;
    const char on = sp.running && (servoed || stretching(sp.prm.domain));
    changed = changed || hon(s) != on;
    hon(s) = on;
    if (!on) continue;
    stretch = true;
    stretch_known_axes(sp.prm.domain, servoed ? &sp.servo.spec : nullptr, sp.prm.integ.dt);
    if (servoed) sp.stale = true;  // a rebuild may have read it within this step
    else speed[s] = stretch_speed(sp.prm.domain, 2 * sp.rmax + sp.prm.skin);
  }
  if (changed) {
    Kokkos::deep_copy(stretching_, hon);  // only when a cell starts or stops stretching
    stretching_sent_ = true;
  }
  if (stretch) stretch_cells(p_, dev_spec_, stretching_, servo_slots_, rows_.data() + kSpeedColumn, kRowWidth);
  ++batch_steps_;
  Kokkos::deep_copy(host_rows_, rows_);
  for (std::size_t s = 0; s < spec_.size(); ++s)
    if (spec_[s].running && spec_[s].servo.on) speed[s] = host_rows_(s, kSpeedColumn);
  // Each specimen's largest overlap past its limit: the contacts the force kernel listed (rarely any), each to its
  // specimen, the larger kept and ties to the later contact (MaxOverlap's rule).
  std::vector<OverlapStat>& worst = worst_of_;
  worst.assign(spec_.size(), OverlapStat());
  int exceeded = 0;
  Kokkos::deep_copy(exceeded, items_.exceeded_count);
  if (exceeded > 0) {
    auto listed = Kokkos::create_mirror_view_and_copy(
        HostSpace(), Kokkos::subview(items_.exceeded, std::make_pair(0, exceeded)));
    Kokkos::deep_copy(items_.exceeded_count, 0);
    for (int k = 0; k < exceeded; ++k) {
      const OverlapStat& o = listed(k);
      const auto owner = std::upper_bound(contact_first_.begin(), contact_first_.end(), o.contact) - 1;
      OverlapStat& w = worst[static_cast<std::size_t>(owner - contact_first_.begin())];
      if (o.ratio > w.ratio || (o.ratio == w.ratio && o.contact > w.contact)) w = o;
    }
  }
  for (std::size_t s = 0; s < spec_.size(); ++s) {
    Specimen& sp = spec_[s];
    if (!sp.running) continue;
    sp.time += sp.prm.integ.dt;
    ++sp.steps;
    sp.wall_disp += speed[s] * sp.prm.integ.dt;
    take_row(static_cast<int>(s), worst[s]);
  }
}

void CellBatch::take_row(int s, const OverlapStat& worst) {
  Specimen& sp = spec_[static_cast<std::size_t>(s)];
  const Real* row = &host_rows_(s, 0);
  sp.stats = step_stats(row);
  const long step = sp.steps - 1;
  std::string why;
  auto gid_of = [&](int i) {
    auto g = Kokkos::create_mirror_view_and_copy(HostSpace(), Kokkos::subview(p_.gid, std::make_pair(i, i + 1)));
    return g(0) - static_cast<std::uint32_t>(sp.first);
  };
  const Real limit = sp.prm.overlap_limit;
  if (worst.contact >= 0 && worst.ratio > limit) {
    auto hi = Kokkos::create_mirror_view_and_copy(
        HostSpace(), Kokkos::subview(balls_.i, std::make_pair(worst.contact, worst.contact + 1)));
    why = overlap_blowup(step, gid_of(hi(0)), false, worst.ratio, limit);
  } else if (row[2] > 0) {
    why = nonfinite_blowup(step, gid_of(non_finite_particle(p_, sp.first, sp.count)), sp.prm.integ.dt, sp.critical_dt);
  } else if (sp.stats.max_move2 > limit * limit) {
    why = fast_blowup(step, gid_of(fastest_ball(p_, sp.first, sp.count, sp.prm.integ.dt)),
                      std::sqrt(sp.stats.max_move2), limit, sp.prm.integ.dt, sp.critical_dt);
  }
  if (why.empty()) return;
  sp.blowup = why;
  stop(s);
}

template <int NV, class F>
std::vector<std::array<Real, NV>> CellBatch::contact_sums(const char* label, const F& f) const {
  static_assert(NV <= 3, "sums_ holds three values a specimen");
  segmented_reduce_lanes_to<NV, 0, 1>(label, owner_tree_, OwnerSums<NV, F>{owners(), f}, sums_.data(), 3);
  Kokkos::deep_copy(host_sums_, sums_);
  std::vector<std::array<Real, NV>> out(spec_.size());
  for (std::size_t s = 0; s < spec_.size(); ++s)
    for (int q = 0; q < NV; ++q) out[s][static_cast<std::size_t>(q)] = host_sums_(s, q);
  return out;
}

template <class F>
const std::vector<std::array<Real, 3>>& CellBatch::per_volume(const char* label, const F& f,
                                                              std::vector<std::array<Real, 3>>& cache,
                                                              long& at) const {
  if (at == batch_steps_) return cache;
  cache.assign(spec_.size(), {});
  at = batch_steps_;
  if (fresh_) return cache;
  read_cells();  // the volumes of the cells as they are now
  cache = contact_sums<3>(label, f);
  for (std::size_t s = 0; s < spec_.size(); ++s) {
    const Real V = spec_[s].prm.domain.volume();
    for (Real& x : cache[s]) x /= V;
  }
  return cache;
}

const std::vector<std::array<Real, 3>>& CellBatch::contact_stress_diagonals() const {
  return per_volume("dem::batch::contact_stress_diagonal",
                    LoveWeberTerms<3, SpecimenImages>{p_.x, SpecimenImages{p_.specimen, dev_spec_}}, stress_, stress_at_);
}

const std::vector<std::array<Real, 3>>& CellBatch::cell_stiffnesses() const {
  return per_volume("dem::batch::cell_stiffness",
                    StiffnessTerms<SpecimenImages>{p_.x, p_.radius, SpecimenImages{p_.specimen, dev_spec_}}, stiffness_,
                    stiffness_at_);
}

Real CellBatch::unbalanced_ratio(int s) const {
  const Specimen& sp = spec_.at(static_cast<std::size_t>(s));
  if (sp.count == 0) return 0;
  if (force_sums_at_ != batch_steps_) {
    force_sums_.assign(spec_.size(), {});
    force_sums_at_ = batch_steps_;
    if (!fresh_) force_sums_ = contact_sums<2>("dem::batch::contact_force_sum", ForceTerms());
  }
  const std::array<Real, 2>& f = force_sums_[static_cast<std::size_t>(s)];
  return dem::unbalanced_ratio(sp.stats.unbalanced, sp.count, f[0], f[1]);
}

long CellBatch::touching(int s) const {
  unbalanced_ratio(s);  // the sums of the step, taken once
  return static_cast<long>(force_sums_[static_cast<std::size_t>(s)][1]);
}

HostParticles CellBatch::balls_of(int s) const {
  const Specimen& sp = spec_.at(static_cast<std::size_t>(s));
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), p_.x);
  auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), p_.v);
  auto w = Kokkos::create_mirror_view_and_copy(HostSpace(), p_.w);
  auto g = Kokkos::create_mirror_view_and_copy(HostSpace(), p_.gid);
  HostParticles h;
  h.x.resize(sp.count);
  h.v.resize(sp.count);
  h.w.resize(sp.count);
  for (int i = sp.first; i < sp.first + sp.count; ++i) {
    const std::size_t k = g(i) - static_cast<std::uint32_t>(sp.first);
    h.x[k] = load(x, i);
    h.v[k] = load(v, i);
    h.w[k] = load(w, i);
  }
  return h;
}

}  // namespace dem
