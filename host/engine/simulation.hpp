#pragma once
/// One DEM system and its time loop: named stages (rebuild, forces, gather, integrate, boundaries),
/// each timed. Boundary control (servos, membrane) steers it from outside through the wall setters.
#include <array>
#include <stdexcept>
#include <string>
#include <vector>

#include "kernels/contact/accumulate.hpp"
#include "kernels/contact/contact_sums.hpp"
#include "kernels/core/reduce.hpp"
#include "kernels/neighbor/binning.hpp"
#include "kernels/neighbor/contact_detect.hpp"
#include "kernels/contact/contact_force.hpp"
#include "kernels/motion/cell_servo.hpp"
#include "kernels/motion/integrate.hpp"
#include "kernels/motion/membrane.hpp"
#include "kernels/motion/wall_servo.hpp"
#include "host/engine/sim_state.hpp"
#include "host/engine/step_rows.hpp"

namespace dem {

/// A run stopped because the state became unphysical. what() names the step, particle and a fix.
struct BlowUp : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct SimParams {
  Domain domain;
  IntegrateParams integ;        ///< dt must be set (see critical_dt)
  Real skin = 0;                ///< Verlet skin (m)
  Real overlap_limit = 0.1;     ///< stop when an overlap exceeds this fraction of the radius
  /// The host reads the steps' statistics (blow-up checks, displacements since the last rebuild) at least every
  /// this many steps, 1 to StepRows::kSlots; in between they stay on the device (host/engine/step_reads.cpp).
  int stats_every = 1;
};

/// Wall-clock seconds spent per part of the step.
struct StageTimes {
  double rebuild = 0;     ///< binning, contact detection and the history's remap
  double forces = 0;      ///< ball-ball contacts
  double integrate = 0;   ///< the gather of each ball's forces and the leapfrog
  double boundaries = 0;  ///< moving walls, membrane nodes or the periodic cell's stretch
  double membrane = 0;    ///< membrane elasticity, pressure, reactions and node integration
  long rebuilds = 0;
  double walls = 0;       ///< ball-wall and ball-facet contacts (platens, mould, membrane)
  /// Rebuilds found due at a step already taken, between two reads of the statistics (step_reads.cpp): a ball
  /// outran the bound on its speed, and a contact may have been missed for the steps in between.
  long late_rebuilds = 0;
  double loop() const { return rebuild + forces + walls + membrane + integrate + boundaries; }
  /// What was spent between an earlier reading `t` and this one.
  StageTimes since(const StageTimes& t) const {
    return {rebuild - t.rebuild,   forces - t.forces,     integrate - t.integrate,
            boundaries - t.boundaries, membrane - t.membrane, rebuilds - t.rebuilds,
            walls - t.walls,       late_rebuilds - t.late_rebuilds};
  }
};

/// What a BlowUp says (step_reads.cpp): a contact's overlap beyond `limit` (a fraction of the radius), a non-finite
/// position, a ball that moved more than `limit` of its radius in one step (`move`). Each names the step, the
/// particle by its gid, the likely cause and a fix.
std::string overlap_blowup(long step, std::uint32_t gid, bool wall, Real ratio, Real limit);
std::string nonfinite_blowup(long step, std::uint32_t gid, Real dt, Real critical);
std::string fast_blowup(long step, std::uint32_t gid, Real move, Real limit, Real dt, Real critical);
/// The local index of the ball of particles [first, first + count) that moves farthest in a step of dt, relative
/// to its radius (a copy of the velocities to the host: for a blow-up's message).
int fastest_ball(const Particles& p, int first, int count, Real dt);

/// Whether neighbour lists of Verlet skin `skin` (m) must be rebuilt after a step with largest squared displacement
/// `disp2` (m^2) since the last rebuild and boundaries moved by `walls` (m): a ball moved half the skin, or a ball and
/// a boundary together the whole skin.
bool lists_expired(Real disp2, Real walls, Real skin);

/// One line for a log: seconds per stage, rebuild count and particle-steps per second of the time loop.
std::string describe(const StageTimes& t, long particles, long steps);

class Simulation {
 public:
  /// table: nmat x nmat contact parameters (row-major); walls and mesh may be empty.
  Simulation(Particles particles, WallSet walls, FacetMesh mesh, const std::vector<ContactParams>& table, int nmat,
             SimParams prm);

  /// One time step. `measure`: fill stats() (unbalanced force, kinetic energy) for this step; the
  /// sums cost a pass of square roots, so unmeasured steps skip them. A measured step's statistics are read at
  /// once, the others' within SimParams::stats_every steps: a blow-up is reported then, with the step it happened at.
  void step(bool measure = true);
  /// nsteps steps; stats() describe the last one.
  void run(long nsteps) { for (long s = 0; s < nsteps; ++s) step(s + 1 == nsteps); }
  /// Times each step's parts, counted once, up to the step numbered `end` (part_sampling.hpp: a stage's first
  /// steps); after it one step in kTimedEvery, counted kTimedEvery times.
  void time_each_step_until(long end) { timed_until_ = end; }

  /// The particles; their f and m are those of the last gather_forces (a step leaves them out).
  Particles& particles() { return p_; }
  const Particles& particles() const { return p_; }
  /// The particles with the last step's contact force and moment of each ball in f and m, gathered at the first call
  /// after a step: only output and states read them, so a step does not store them (integrate.hpp: gather_forces).
  const Particles& particles_with_forces() const;
  const ContactList& ball_contacts() const { return balls_; }
  /// The contacts by their particles (contact_sums.hpp), for sums that do not depend on when the lists were rebuilt.
  ContactOwners contact_owners() const {
    return {balls_, wall_c_, own_, adj_walls_.offset, adj_walls_.entry, integ_.gid2local};
  }
  /// N sums of Terms' terms over the touching contacts, per particle and then in gid order (OwnerSums), to `out`.
  template <int N, class Terms>
  void owner_sums(const char* label, const Terms& terms, Real (&out)[N]) const {
    const int gids = static_cast<int>(integ_.gid2local.extent(0));
    deterministic_reduce_lanes<N, 0, 1>(label, gids, OwnerSums<N, Terms>{contact_owners(), terms}, out);
  }
  /// The same, left in device memory at `root` (a servo on the device reads them there).
  template <int N, class Terms>
  void owner_sums_to(const char* label, const Terms& terms, Real* root) const {
    const int gids = static_cast<int>(integ_.gid2local.extent(0));
    deterministic_reduce_lanes_to<N, 0, 1>(label, gids, OwnerSums<N, Terms>{contact_owners(), terms}, root);
  }
  const ContactList& wall_contacts() const { return wall_c_; }
  /// The last step's statistics (read from the device where they wait).
  const StepStats& stats() const {
    read_rows();
    return stats_;
  }
  const StageTimes& times() const { return times_; }
  /// The stage times of the run segments before a resume, so that reports cover the whole run.
  void set_times(const StageTimes& t) { times_ = t; }
  /// The parameters; their domain is the cell as the host last knew it: domain() is the cell now.
  const SimParams& params() const { return prm_; }
  /// The material-pair table of the contact laws, on the device (nmat x nmat).
  const ParamTableView& contact_table() const { return params_; }
  long step_count() const { return step_; }
  Real time() const { return time_; }
  int num_walls() const { return walls_.n; }
  const WallSet& walls() const { return walls_; }
  const FacetMesh& mesh() const { return mesh_; }

  /// Largest stable time step estimate (s): min over particles of sqrt(m/kn) and sqrt(I/k_rot) for the
  /// stiffest (ball-wall) contact; the caller multiplies by a safety factor.
  Real critical_dt() const;
  /// Replaces the contact laws (same nmat x nmat layout as the constructor's); contact history is kept.
  void set_contact_params(const std::vector<ContactParams>& table);
  void set_dt(Real dt) { prm_.integ.dt = dt; }
  /// Local damping about the mean flow v = rate (x - origin) from now on (IntegrateParams::about_flow).
  void set_damping_flow(const Vec3& rate, const Vec3& origin) {
    prm_.integ.about_flow = true;
    prm_.integ.flow_rate = rate;
    prm_.integ.flow_origin = origin;
  }

  /// Makes the facet mesh a flexible membrane (m.mesh must be the mesh given to the constructor: the
  /// Views are shared). Each step then loads its nodes with CST elasticity, the cell pressure and the
  /// ball reactions, and advances their velocities; move_boundaries moves them (prm.move_nodes is forced off).
  void set_membrane(const Membrane& m, const MembraneIntegrateParams& prm);
  /// Cell pressure on the membrane (Pa), positive towards the axis.
  void set_cell_pressure(Real p) { cell_pressure_ = p; }
  Membrane& membrane() { return membrane_; }
  const MembraneStepStats& membrane_stats() const {
    read_rows();
    return membrane_stats_;
  }

  /// Homogeneous deformation of a periodic cell: each step the cell and the particle positions are
  /// stretched about domain.lo by (1 + rate dt) along each axis (1/s, extension positive). Ends a servo on the
  /// device (set_cell_servo).
  void set_strain_rate(const Vec3& rate);
  /// The cell's rates set before each step by the strain-rate servo `spec` on the device, from the next step until
  /// set_strain_rate (kernels/motion/cell_servo.hpp): a kernel sums the contact stress (and the stiffness on one
  /// step in spec.stiffness_every, from the first) and sets the rates, with the host's arithmetic (host/triax's
  /// CellServo) and its bits, and the host waits for none of it. The host reads the cell when asked for it (domain(),
  /// axis_length of a servoed axis, a rebuild). Throws std::invalid_argument unless the cell is periodic along x, y
  /// and z.
  void set_cell_servo(const CellServoSpec& spec);
  /// Stops the servo on the device where one runs, leaving the rates it set last (no copy: a stage that stops early).
  void end_cell_servo() { servo_on_ = false; }
  /// The cell now: read from the device where the servo on the device has changed it since the last read.
  const Domain& domain() const {
    read_cell();
    return prm_.domain;
  }
  /// The cell's length along axis d (m): an axis the servo on the device does not steer the host knows without a read.
  Real axis_length(int d) const;
  /// Love-Weber stress of the ball-ball contacts over `volume` (m^3), compression positive, row-major
  /// 3 x 3 (Pa): sigma = -(1/V) sum fc (x) (x2 - x1). Boundary (wall, facet) contacts are not included.
  std::array<Real, 9> contact_stress(Real volume) const;
  /// Its diagonal (xx, yy, zz) alone, bit for bit the same values, at a third of the sums: a servo's every step.
  std::array<Real, 3> contact_stress_diagonal(Real volume) const;
  /// The cell servo's stiffness K_dd = (1/V) sum_c (Fn/overlap) l_d^2 over the touching ball-ball contacts (Pa), V
  /// the cell's volume: what CellBatch::cell_stiffnesses gives a batch's specimens.
  std::array<Real, 3> cell_stiffness() const;

  /// Rigid wall velocity (m/s) and position (m) control. Setting a velocity ends a servo on the device.
  void set_wall_velocity(int w, const Vec3& v);
  /// Wall spec.wall's velocity (and its tied nodes') set before each step by the stress servo `spec` on the device,
  /// from the next step until end_wall_servo or a velocity set (kernels/motion/wall_servo.hpp): a kernel reads the
  /// wall's load and sets the velocity, with the host's arithmetic and its bits, and the host waits for none of it. The
  /// host reads the walls when asked for them (wall_point, wall_velocity, a state).
  void set_wall_servo(const WallServoSpec& spec);
  /// Ends it, leaving the velocity it set last.
  void end_wall_servo() { wall_servo_on_ = false; }
  /// Every analytic wall's velocity at once (one per wall), in one copy to the device: a servo's every step.
  void set_wall_velocities(const std::vector<Vec3>& v);
  Vec3 wall_velocity(int w) const;
  Vec3 wall_point(int w) const;
  void set_wall_point(int w, const Vec3& p);
  /// What the balls load each wall object with: the force (N) and the touching contacts, analytic walls first,
  /// then the facets where `facets` (a servo needs its wall alone, and a membrane has thousands of facets). One
  /// launch and one copy to the host.
  struct WallLoads {
    std::vector<Vec3> force;
    std::vector<int> touching;
  };
  WallLoads wall_loads(bool facets = true) const;
  /// Force exerted by the balls on each wall object (analytic walls first, then facets), N.
  std::vector<Vec3> wall_forces() const { return wall_loads().force; }
  /// Touching contacts on each wall object (analytic walls first, then facets).
  std::vector<int> wall_contact_counts() const { return wall_loads().touching; }

  /// Mean unbalanced force over mean contact force (YADE/PFC definition) after the last measured step;
  /// 1 when there are no contacts.
  Real unbalanced_ratio() const;
  /// Number of touching contacts (ball-ball, ball-wall).
  std::array<long, 2> touching() const;

  /// The whole dynamic state, for a checkpoint (host/engine/sim_state.cpp).
  SimState state() const;
  /// Continues from a state taken from a Simulation built the same way (same balls, walls, mesh and laws):
  /// the next steps are bit for bit those the original would have taken. Throws std::runtime_error when
  /// the counts of balls, walls or mesh nodes differ.
  void restore(const SimState& s);

 private:
  Particles p_;
  // The cell in device memory, which the kernels read (SpecimenTable::cell); the host's copy is prm_.domain. The host
  // moves its copy as the device moves its own, so that they stay equal bit for bit, except for the axes a servo on the
  // device steers: the host reads those when it needs them (read_cell), hence the mutable copy.
  CellView cell_;
  CellServoSumsView servo_sums_;
  CellServoSpec servo_;
  bool servo_on_ = false;
  long servo_calls_ = 0;
  mutable bool cell_stale_ = false;
  // A servo on the device steering a wall: the host's copies of the walls (hwall_*) are read when asked for.
  WallServoSpec wall_servo_;
  bool wall_servo_on_ = false;
  mutable bool walls_stale_ = false;
  WallSet walls_;
  decltype(Kokkos::create_mirror(WallSet().point)) hwall_point_, hwall_vel_;
  FacetMesh mesh_;
  ParamTableView params_;
  mutable SimParams prm_;
  CellList cells_;
  ContactList balls_, wall_c_;
  ListBuffers ball_bufs_, wall_bufs_;
  FacetBins facet_bins_;
  Adjacency adj_balls_, adj_walls_;
  Index2View own_;
  IndexView obj_offsets_;
  IntegrateScratch integ_;  ///< with the map from gid to the particles' order, renewed at each rebuild
  // wall_loads' device scratch and the host's copies of it: a copy of their own even where the device is the host,
  // so that a read is a copy there too and the sync counts (sync_counts.hpp) are the GPU's.
  mutable WallLoadView wall_load_;
  mutable decltype(Kokkos::create_mirror(WallLoadView())) hwall_load_;
  Membrane membrane_;
  MembraneIntegrateParams membrane_prm_;
  Vec3View membrane_f_;
  Real cell_pressure_ = 0;
  // The steps' statistics: on the device in rows_, and on the host up to step read_to_ (step_reads.cpp). Reading
  // them changes nothing but when the host learns them, so the reader and what it fills are mutable.
  mutable StepRows rows_;
  mutable long read_to_ = 0;
  mutable StepStats stats_;
  mutable MembraneStepStats membrane_stats_;
  mutable Real wall_disp_ = 0;       ///< how far a wall, the cell or a membrane node has moved since the rebuild (m)
  mutable Real step_bound_ = 0;      ///< the farthest one ball moved in a step of the last read (m); 0: no read yet
  mutable Real node_bound_ = 0;      ///< the fastest membrane node of the last read (m/s)
  mutable Real unread_travel_ = 0;   ///< bound on the boundaries' travel in the steps not yet read (m)
  /// The host-known part of each step's boundary speed (walls, the cell's stretch; m/s) and its dt, by ring slot.
  struct BoundaryStep {
    Real speed = 0, dt = 0;
    bool cell = false;  ///< the cell's speed is on the step's row (StepRows::kCellSpeed): a servo on the device set it
    bool wall = false;  ///< a wall's likewise (StepRows::kWallSpeed)
  };
  std::array<BoundaryStep, StepRows::kSlots> boundary_steps_{};
  mutable StageTimes times_;
  Real rmax_ = 0;
  long step_ = 0;
  long timed_until_ = 0;  ///< time_each_step_until
  Real time_ = 0;
  bool fresh_ = true;
  mutable bool forces_current_ = true;  ///< p_.f and p_.m hold the last step's gathered forces

  Gather gather() const { return make_gather(balls_, own_, adj_balls_, wall_c_, adj_walls_); }
  bool rebuild_due();
  /// Records the step's host-known boundary speed (m/s) and dt, and adds to the bound on the unread steps' travel
  /// (`cell_bound`, `wall_bound`, m/s, where the cell's or a wall's speed is on the row: its bound; else negative).
  void boundary_step(Real speed, Real dt, Real cell_bound, Real wall_bound);
  /// Reads the rows of the steps not yet read: their blow-up checks, displacements and statistics.
  void read_rows() const;
  /// Whether the neighbour lists must be rebuilt after a step with largest displacement^2 `disp2` since the last
  /// rebuild and boundaries moved by `walls` (m).
  bool lists_expired(Real disp2, Real walls) const;
  void rebuild();
  void index_contacts();  ///< owner ranges, adjacency and object offsets of the contact lists
  void move_boundaries();
  /// The kernels' one specimen: the cell in device memory, the time integration.
  SpecimenTable specimen() const;
  /// The servo on the device's sums and rates, before a step.
  void servo_step();
  /// The host's copy of the cell to the device / the device's to the host where it is stale.
  void upload_cell();
  void read_cell() const;
  /// The walls' points and velocities from the device, where a servo on the device has moved one since the last read.
  void read_walls() const;
  /// Sets the host's copy of wall w's velocity; false where it was v already.
  bool store_wall_velocity(int w, const Vec3& v);
  /// Throws BlowUp where step `step`'s statistics and overlaps show one.
  void check_blowup(long step, const StepStats& st, const OverlapStat& ob, const OverlapStat& ow) const;
};

}  // namespace dem
