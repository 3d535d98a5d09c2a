// The host's reads of the steps' statistics (host/engine/step_rows.hpp), and the decisions taken from them: blow-ups
// and the neighbour lists' rebuild.
//
// The rebuild between reads. The lists hold every pair within the skin at the last rebuild, so they stay valid while
// no ball has moved more than half the skin since, and no ball more than the skin less the boundaries' travel
// (lists_expired). After a read the host knows the displacement d and, for each unread step since, bounds it by
// d + (steps since) * kSpeedGrowth * u, where u is the farthest any ball moved in one step over the last read's steps;
// the membrane nodes' travel likewise, and the walls' and the cell's exactly (the host sets them). While the bounds
// cannot expire the lists, no rebuild can be due, and the step goes on without a read. Once they can, the rows are
// read and the decision is the exact one, taken at the same step as it would be with a read at every step. So the
// steps are bit for bit those of stats_every = 1, unless a ball speeds up more than kSpeedGrowth times within a read's
// steps: the read then finds the lists expired at an earlier step (a late rebuild, counted in StageTimes and reported
// once on stderr), and the run differs from there.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "host/engine/simulation.hpp"

namespace dem {

namespace {
/// How much faster than the fastest ball of the last read a ball may go before the bound fails (see above). A step
/// of quasi-static DEM changes a ball's speed by a small fraction; 2 leaves room for a servo's kick.
constexpr Real kSpeedGrowth = 2;
/// The bounds are compared with this margin, larger than their rounding, so that a bound that holds is never
/// taken for one that fails the exact test by a rounding.
constexpr Real kBoundMargin = 1e-9;
}  // namespace

bool lists_expired(Real disp2, Real walls, Real skin) {
  const Real d = std::sqrt(disp2);
  return 2 * d > skin || d + walls > skin;
}

bool Simulation::lists_expired(Real disp2, Real walls) const { return dem::lists_expired(disp2, walls, prm_.skin); }

bool Simulation::rebuild_due() {
  if (fresh_) return true;
  const long unread = step_ - read_to_;
  if (unread > 0 && step_bound_ > 0) {
    const Real d = std::sqrt(stats_.max_disp2) + static_cast<Real>(unread) * kSpeedGrowth * step_bound_;
    const Real margin = 1 + kBoundMargin;
    if (!lists_expired(d * d * margin * margin, (wall_disp_ + unread_travel_) * margin)) return false;
  }
  read_rows();
  return lists_expired(stats_.max_disp2, wall_disp_);
}

void Simulation::boundary_step(Real speed, Real dt, Real cell_bound, Real wall_bound) {
  boundary_steps_[static_cast<std::size_t>(StepRows::slot(step_))] = {speed, dt, cell_bound >= 0, wall_bound >= 0};
  unread_travel_ +=
      std::max({speed, cell_bound, wall_bound, mesh_.ntri > 0 ? kSpeedGrowth * node_bound_ : Real(0)}) * dt;
}

void Simulation::read_rows() const {
  if (read_to_ == step_) return;
  rows_.read(read_to_, step_);
  Real step_max2 = 0, node_max = 0;
  bool late = false;
  for (long s = read_to_; s < step_; ++s) {
    const Real* row = rows_.host_row(s);
    StepStats st = step_stats(row + StepRows::kLeapfrog);
    if (row[StepRows::kLeapfrog + 2] > 0) st.bad = non_finite_particle(p_);
    try {
      check_blowup(s, st, rows_.host_overlap(s, StepRows::kBalls), rows_.host_overlap(s, StepRows::kWalls));
    } catch (const BlowUp&) {
      // Reported once: saving the blown-up state for inspection (state(), a snapshot) reads no row again, where it
      // threw a second time and the job ended without its checkpoint.
      read_to_ = step_;
      throw;
    }
    const BoundaryStep& b = boundary_steps_[static_cast<std::size_t>(StepRows::slot(s))];
    Real speed = b.speed;
    if (b.cell) speed = std::max(speed, row[StepRows::kCellSpeed]);
    if (b.wall) speed = std::max(speed, row[StepRows::kWallSpeed]);
    if (mesh_.ntri > 0) {
      speed = std::max(speed, row[StepRows::kNodeSpeed]);
      node_max = std::max(node_max, row[StepRows::kNodeSpeed]);
      membrane_stats_ = dem::membrane_stats(row + StepRows::kMembrane);
    }
    wall_disp_ += speed * b.dt;
    step_max2 = std::max(step_max2, st.max_step2);
    stats_ = st;
    // Step s + 1's decision was taken before this read (by the bound) unless s is the last step.
    if (s + 1 < step_ && lists_expired(st.max_disp2, wall_disp_)) late = true;
  }
  read_to_ = step_;
  unread_travel_ = 0;
  step_bound_ = std::sqrt(step_max2);
  node_bound_ = node_max;
  if (late) {
    if (times_.late_rebuilds == 0)
      std::fprintf(stderr,
                   "triaxdem: at step %ld the neighbour lists were found expired some steps late: a ball moved more "
                   "than %.0f times faster than the fastest of the steps before, between two reads of the statistics. "
                   "Contacts may have been missed for those steps; [solver] stats_every = 1 reads them every step\n",
                   step_, static_cast<double>(kSpeedGrowth));
    ++times_.late_rebuilds;
  }
}

std::string overlap_blowup(long step, std::uint32_t gid, bool wall, Real ratio, Real limit) {
  std::ostringstream msg;
  msg << "blow-up at step " << step << ": particle " << gid << " overlaps " << (wall ? "a wall" : "another particle")
      << " by " << ratio * 100 << "% of its radius (limit " << limit * 100
      << "%). Likely cause: stiffness too low for the load, a wall or servo moving too fast, or too large a time "
         "step; suggested fix: raise emod, lower the wall speed or servo gain, or lower [solver] dt_safety";
  return msg.str();
}

std::string nonfinite_blowup(long step, std::uint32_t gid, Real dt, Real critical) {
  std::ostringstream msg;
  msg << "blow-up at step " << step << ": particle " << gid
      << " has a non-finite position. Likely cause: time step above the critical one or a servo gain too high; "
         "suggested fix: lower [solver] dt_safety (now dt = "
      << dt << " s, critical " << critical << " s)";
  return msg.str();
}

std::string fast_blowup(long step, std::uint32_t gid, Real move, Real limit, Real dt, Real critical) {
  std::ostringstream msg;
  msg << "blow-up at step " << step << ": particle " << gid << " moved " << move * 100
      << "% of its radius in one step (limit " << limit * 100
      << "%, the overlap limit): its kinetic energy jumped beyond what the loads can give. Likely cause: a time "
         "step above the critical one for the stiffness reached, or a servo gain or wall speed too high; "
         "suggested fix: lower [solver] dt_safety (now dt = "
      << dt << " s, critical " << critical << " s) or the servo gain";
  return msg.str();
}

int fastest_ball(const Particles& p, int first, int count, Real dt) {
  auto hv = Kokkos::create_mirror_view_and_copy(HostSpace(), p.v);
  auto hr = Kokkos::create_mirror_view_and_copy(HostSpace(), p.radius);
  int fast = first;
  Real worst_move = -1;
  for (int i = first; i < first + count; ++i) {
    const Real move = norm(load(hv, i)) * dt / hr(i);
    if (move > worst_move) worst_move = move, fast = i;
  }
  return fast;
}

void Simulation::check_blowup(long step, const StepStats& st, const OverlapStat& ob, const OverlapStat& ow) const {
  const OverlapStat& worst = ob.ratio >= ow.ratio ? ob : ow;
  const Real limit2 = prm_.overlap_limit * prm_.overlap_limit;
  if (worst.ratio <= prm_.overlap_limit && st.bad < 0 && st.max_move2 <= limit2) return;
  if (worst.ratio > prm_.overlap_limit) {
    // The contact lists have not changed since the step: a rebuild waits for the rows to be read.
    const bool wall = ow.ratio > ob.ratio;
    const ContactList& c = wall ? wall_c_ : balls_;
    auto hi = Kokkos::create_mirror_view_and_copy(HostSpace(), Kokkos::subview(c.i, std::make_pair(worst.contact, worst.contact + 1)));
    auto hg = Kokkos::create_mirror_view_and_copy(HostSpace(), Kokkos::subview(p_.gid, std::make_pair(hi(0), hi(0) + 1)));
    throw BlowUp(overlap_blowup(step, hg(0), wall, worst.ratio, prm_.overlap_limit));
  }
  auto hg = Kokkos::create_mirror_view_and_copy(HostSpace(), p_.gid);
  if (st.bad >= 0) throw BlowUp(nonfinite_blowup(step, hg(st.bad), prm_.integ.dt, critical_dt()));
  // A ball that moves this far in one step would overlap anything it meets by more than the overlap limit. The
  // fastest ball now (the rows are read up to stats_every steps after the step) is named.
  const int fast = fastest_ball(p_, 0, p_.n, prm_.integ.dt);
  throw BlowUp(fast_blowup(step, hg(fast), std::sqrt(st.max_move2), prm_.overlap_limit, prm_.integ.dt, critical_dt()));
}

}  // namespace dem
