#pragma once
/// Independent periodic cells stepped side by side: a calibration's or a diagnosis's many small cells as one set of
/// particles and contacts, one launch per kernel for all of them, where each alone would use a sliver of a GPU.
///
/// Each specimen's steps are bit for bit those of its own Simulation:
///  - the kernels are the same, each work item with its specimen's cell, time step and laws (kernels/core/specimen.hpp);
///  - each specimen's sums are its own tree, as alone (segmented reductions, kernels/core/reduce.hpp);
///  - a run's bits do not depend on when its neighbour lists are rebuilt (contact_sums.hpp, step_wrap), so all the
///    running specimens are rebuilt together when one is due; a stopped one's particles and lists are kept as they
///    are (bin_specimens).
/// The statistics are read every step (stats_every 1), for every specimen in one copy.
#include <array>
#include <string>
#include <vector>

#include "host/engine/builder.hpp"
#include "host/engine/simulation.hpp"

namespace dem {

class CellBatch {
 public:
  /// The specimens: Simulations of a periodic cell (make_periodic_simulation) not yet stepped, fully periodic,
  /// without walls or facets, all with the same number of materials. Their particles, laws and settings are copied;
  /// the Simulations are not used after. Throws std::invalid_argument naming the specimen and what is wrong.
  explicit CellBatch(const std::vector<const Simulation*>& specimens);

  int size() const { return static_cast<int>(spec_.size()); }
  long balls() const { return p_.n; }
  int balls(int s) const { return spec_.at(static_cast<std::size_t>(s)).count; }
  Real dt(int s) const { return spec_.at(static_cast<std::size_t>(s)).prm.integ.dt; }
  /// One step of every running specimen. measure[s]: whether specimen s's step fills its unbalanced force and
  /// kinetic energy (Simulation::step's `measure`); empty: every one. A specimen whose step blows up is stopped
  /// (blowup() says why) and the others go on.
  void step(const std::vector<char>& measure = {});

  /// Stops specimen s: its state stays as it is, and the steps leave it out.
  void stop(int s);
  bool running(int s) const { return spec_.at(static_cast<std::size_t>(s)).running; }
  int running_count() const;
  /// Why specimen s stopped with a blow-up (the message its own Simulation's BlowUp gives), or "".
  const std::string& blowup(int s) const { return spec_.at(static_cast<std::size_t>(s)).blowup; }

  /// Specimen s's cell now: read from the device where its servo on the device changed it since the last read.
  const Domain& domain(int s) const;
  /// Its length along axis d (m): an axis its servo on the device does not steer is known without a read.
  Real axis_length(int s, int d) const;
  /// As Simulation::set_strain_rate, for specimen s (its servo on the device ends).
  void set_strain_rate(int s, const Vec3& rate);
  /// As Simulation::set_cell_servo, for specimen s: before each of its steps a kernel sets its rates, the batch's
  /// servos in one launch after two reductions for all of them, with no wait of the host.
  void set_cell_servo(int s, const CellServoSpec& spec);
  /// Steps specimen s has taken, and its time (s).
  long step_count(int s) const { return spec_.at(static_cast<std::size_t>(s)).steps; }
  Real time(int s) const { return spec_.at(static_cast<std::size_t>(s)).time; }
  /// Specimen s's last step's statistics.
  const StepStats& stats(int s) const { return spec_.at(static_cast<std::size_t>(s)).stats; }
  /// Rebuilds of specimen s's lists: every one of the batch's while it runs.
  long rebuilds(int s) const { return spec_.at(static_cast<std::size_t>(s)).rebuilds; }
  /// Steps the batch has taken, and of them those with a rebuild.
  long steps() const { return batch_steps_; }
  long rebuild_steps() const { return rebuild_steps_; }
  /// Every specimen's Love-Weber stress diagonal (xx, yy, zz; Pa) over its cell's volume: what
  /// Simulation::contact_stress_diagonal gives each alone, in one launch and one copy (kept until the next step).
  const std::vector<std::array<Real, 3>>& contact_stress_diagonals() const;
  /// Every specimen's servo stiffness K_dd (Pa): what Simulation::cell_stiffness gives each alone (kept until the next
  /// step).
  const std::vector<std::array<Real, 3>>& cell_stiffnesses() const;
  /// Specimen s's unbalanced-force ratio and touching ball-ball contacts: Simulation::unbalanced_ratio and
  /// touching()[0] alone (all specimens' sums in one launch, kept until the next step).
  Real unbalanced_ratio(int s) const;
  long touching(int s) const;
  /// Specimen s's balls by their gid in its own Simulation: positions, velocities and spins (for comparisons).
  HostParticles balls_of(int s) const;

 private:
  struct Specimen {
    SimParams prm;
    int first = 0, count = 0;
    Real rmax = 0;
    Real critical_dt = 0;  ///< s, its Simulation's critical_dt (for a blow-up's message)
    Real time = 0;
    long steps = 0;
    long rebuilds = 0;
    StepStats stats;
    Real wall_disp = 0;  ///< the cell's travel since the specimen's last rebuild (m), as Simulation's
    bool running = true;
    std::string blowup;
    CellServoSlot servo;  ///< its servo on the device, as the host knows it (calls counted alike)
    bool stale = false;   ///< the device's cell has changed since the host last read it (its servo's axes)
  };
  Particles p_;
  ParamTableView params_;
  int nmat_ = 0;
  // The host's copies of the cells are read from the device when asked for (read_cells): mutable.
  mutable std::vector<Specimen> spec_;
  SpecimenParamsView dev_spec_;
  mutable decltype(Kokkos::create_mirror_view(SpecimenParamsView())) host_spec_;
  CellList cells_;
  ContactList balls_, walls_;
  ListBuffers ball_bufs_;
  Index2View own_;
  IntegrateScratch integ_;  ///< with the map from gid to the particles' order, renewed at each rebuild
  Adjacency adj_balls_, adj_walls_;
  ContactItems items_;
  std::vector<int> contact_first_;  ///< S + 1 offsets of the specimens' contacts (host copy)
  /// The leapfrog's tree, of the running specimens' particles, and the contact sums' (OwnerSums), of every specimen's
  /// gids (a stopped specimen's stress is that of its state).
  SegmentedTree particle_tree_, owner_tree_;
  ContactOwners owners() const { return {balls_, walls_, own_, IndexView(), IndexView(), integ_.gid2local}; }
  StepRowsView rows_;  ///< a row per specimen: its Leapfrog values, its cell's stretch speed where a servo set it
  decltype(Kokkos::create_mirror_view(StepRowsView())) host_rows_;
  Kokkos::View<OverlapStat, MemSpace> worst_;  ///< the force kernel's largest overlap of all, not read: see exceeded
  Kokkos::View<OverlapStat*, MemSpace> exceeded_buf_;  ///< room for ContactItems::exceeded
  long batch_steps_ = 0, rebuild_steps_ = 0;
  mutable bool dirty_ = true;  ///< the host's specimen table differs from the device's (upload)
  Kokkos::View<Real**, Kokkos::LayoutRight, MemSpace> sums_;  ///< the per-specimen sums' roots, S x 3
  decltype(Kokkos::create_mirror_view(Kokkos::View<Real**, Kokkos::LayoutRight, MemSpace>())) host_sums_;
  /// Each specimen's NV sums of the terms of f (contact_sums.hpp: OwnerSums) over its contacts, to the host: one
  /// launch per level, one copy.
  template <int NV, class F>
  std::vector<std::array<Real, NV>> contact_sums(const char* label, const F& f) const;
  /// Each specimen's three sums of f over its contacts, over its cell's volume, kept in `cache` until the next step
  /// (`at`: the batch step they were taken after).
  template <class F>
  const std::vector<std::array<Real, 3>>& per_volume(const char* label, const F& f,
                                                     std::vector<std::array<Real, 3>>& cache, long& at) const;
  /// A step's host scratch, kept so that a step allocates nothing on the host either: each specimen's cell's travel
  /// speed, its largest overlap past its limit.
  std::vector<Real> speed_;
  std::vector<OverlapStat> worst_of_;
  /// The per-specimen sums of the last step, and the batch step they were taken after (-1: none).
  mutable std::vector<std::array<Real, 3>> stress_, stiffness_;
  mutable std::vector<std::array<Real, 2>> force_sums_;  ///< sum |f| and touching count of the ball-ball contacts
  mutable long stress_at_ = -1, stiffness_at_ = -1, force_sums_at_ = -1;
  Kokkos::View<char*, MemSpace> stretching_;  ///< which specimens' cells stretch this step
  decltype(Kokkos::create_mirror_view(Kokkos::View<char*, MemSpace>())) host_stretching_;
  bool stretching_sent_ = false;  ///< the device has the host's stretching flags
  CellServoSlotView servo_slots_;
  decltype(Kokkos::create_mirror_view(CellServoSlotView())) host_slots_;
  CellServoSumRowsView servo_sums_;
  bool fresh_ = true;

  /// The servos on the device before a step: their specimens' sums and rates.
  void servo_step();
  /// The slots of the servos to the device (when one starts or ends).
  void upload_slots();
  /// The cells the device has changed to the host's copies (one copy), where any has.
  void read_cells() const;

  /// Rebuilds the running specimens' lists, keeping the stopped ones'.
  void rebuild();
  /// The work items and trees of the running specimens' particles and contacts.
  void plan();
  /// Specimen s's statistics after a step: its blow-up checks (it stops on one; `worst`: its largest overlap past
  /// its limit, if any).
  void take_row(int s, const OverlapStat& worst);
  /// The host's specimen table to the device, where it changed (a cache of the host's: so const).
  void upload() const;
};

}  // namespace dem
