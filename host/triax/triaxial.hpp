#pragma once
/// The drained triaxial test of Tang et al. (2025), Sec. 3.3, on a specimen from multilayer compaction:
/// the rigid mould is replaced by a flexible membrane (tied to the platens) under the cell pressure, the
/// specimen is consolidated isotropically with the top platen under stress servo, then sheared with the
/// top platen at constant velocity and the cell pressure held, to the end strain.
#include <vector>

#include "host/engine/checkpoint.hpp"
#include "host/config/config.hpp"
#include "host/triax/micro_report.hpp"
#include "host/triax/specimen.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/data/measured.hpp"
#include "host/engine/simulation.hpp"
#include "host/engine/stage_loop.hpp"

namespace dem {

/// One record of the shear stage. Stresses compression positive.
struct TriaxialRecord {
  Real eps_a = 0;       ///< (h0 - h) / h0
  Real eps_v = 0;       ///< (V0 - V) / V0, from the membrane's enclosed volume (compression positive)
  Real sigma1 = 0;      ///< Pa, top platen force / platen area
  Real sigma1_bottom = 0;  ///< Pa, the same from the bottom platen (a check of equilibrium)
  Real q = 0;           ///< Pa, sigma1 - sigma3
  Real sigma3_balls = 0;   ///< Pa, lateral stress the balls exert on the membrane (cell pressure + membrane)
  Real eps_v_envelope = 0; ///< (V0 - V) / V0 of the balls' envelope (a check of eps_v without the membrane)
  Real unbalanced = 0;
  Real kinetic = 0;     ///< J
  // The deviator as labs report it (docs/running.md, "Which q"): the top platen force over another area.
  Real q_area = 0;      ///< Pa, over the right-cylinder area A0 (1 - eps_v) / (1 - eps_a) = V / h
  Real q_parabolic = 0; ///< Pa, over the mid-height area of a parabolic barrel
  Real q_membrane = 0;  ///< Pa, q_area less what the membrane adds: sigma3_balls, not the cell pressure
  Real sigma3_hoop = 0; ///< Pa, cell pressure + a lab's thin-shell estimate of the membrane's hoop stress
  // The specimen's mean stress, over the enclosed volume V.
  Real q_lw = 0, p_lw = 0;              ///< Pa, Love-Weber stress of every contact (platens, membrane included)
  Real q_boundary = 0, p_boundary = 0;  ///< Pa, from the boundary contacts alone (stress.hpp: specimen_stress)
  /// Pa, (1/V) sum_p x_p (x) F_p of the balls' net contact forces F_p (what inertia, damping and weight leave
  /// unbalanced), by which the average-stress theorem has the Love-Weber stress exceed the boundary's.
  Real q_net = 0, p_net = 0;
};

struct TriaxialResult {
  Real void_ratio_consolidated = 0;
  long consolidation_steps = 0;
  Real shear_rate = 0;         ///< 1/s
  Real inertial_number = 0;
  std::vector<TriaxialRecord> records;
  std::vector<MicroRow> micro;   ///< with each record when [micro] is enabled
  /// From the records as measured curves are summarised (summarised, host/data/measured.hpp): the peak of the
  /// moving mean of q, q_end the mean over the last 1% of strain, the dilatancy over 0.5% windows.
  Real q_peak = 0, eps_a_peak = 0, phi_peak_deg = 0;
  Real q_end = 0, max_dilatancy = 0;  ///< max of -d eps_v / d eps_a
  std::size_t highest_record = 0;  ///< index of the highest q in records (where micro_*_peak was written)
  int escaped = 0;             ///< balls whose centre ended outside the membrane (should be 0)
  double wall_seconds = 0;
  StageTimes times;            ///< time loop of consolidation and shear, per stage
  std::vector<StageTiming> stages;  ///< the stages run by this process (a resumed run's later ones only)
  long steps = 0;              ///< time steps of consolidation and shear
  long balls = 0;
};

/// The record's field that holds q as a lab reporting `m` computes it.
Real TriaxialRecord::*q_field(QMeasure m);

/// The shear's curves with q from the records' field `q` (q_field(m), or q_lw), eps_v from the membrane,
/// summarised like measured curves.
TriaxialTest curves_of(const TriaxialResult& r, Real TriaxialRecord::*q, Real sigma3);

/// Runs consolidation and shear on `specimen`; writes series and snapshots to `out` when given. With a
/// `plan`: checkpoints (the simulation, the stage, the records and the output so far) as it says, continues
/// from plan->from when set (bit for bit the run that was not stopped), and throws RunStopped after the
/// checkpoint of a signal or of plan->stop_at_step.
TriaxialResult run_triaxial(const Config& cfg, const Specimen& specimen, io::Output* out, bool verbose,
                            CheckpointPlan* plan = nullptr);

/// The shear stage's platen motion: strain rate (1/s) from the inertial number, the steps of its start-up ramp and
/// the steps to the end strain, at time step `dt`.
struct ShearPlan {
  Real rate = 0;
  long ramp = 0, steps = 0;
};
ShearPlan shear_plan(const Config& cfg, Real dt);

}  // namespace dem
