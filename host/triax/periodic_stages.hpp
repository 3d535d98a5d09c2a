#pragma once
/// The periodic test's stages as objects on a cell (host/triax/cell_control.hpp), so that one Simulation
/// (periodic_triaxial.cpp, through run_stage) and a batch of them (periodic_batch.cpp) step the same code.
/// Internal to host/triax/.
#include <array>
#include <string>
#include <vector>

#include "host/engine/stage_loop.hpp"
#include "host/triax/cell_control.hpp"
#include "host/triax/periodic_triaxial.hpp"
#include "host/util/progress.hpp"

namespace dem {

/// Mean diameter (m), effective density (kg/m^3, x mass_scale) and solid volume (m^3) of the balls.
struct GrainScales {
  Real d = 0, rho_eff = 0, v_solid = 0;
};

GrainScales grain_scales(Simulation& sim);

/// The result's parameters and grain figures before the test (`g` receives these), and its first line when verbose.
PeriodicTriaxialResult start_result(Simulation& sim, const PeriodicTriaxialParams& prm, GrainScales& g);

/// The strain-rate servo of the cell (kernels/motion/cell_servo.hpp), called before each step of a stage: on the
/// device where the cell takes it (from the first call on), else on the host, each call measuring the contact stress
/// and setting the next step's rates, with the same arithmetic.
class CellServo {
 public:
  explicit CellServo(const CellServoSpec& spec) : spec_(spec) {}

  void update(CellControl& cell);

 private:
  CellServoSpec spec_;
  bool on_device_ = false;
  long calls_ = 0;
  std::array<Real, 3> k_{};
};

/// The servo of stage (a): every axis to sigma3, its rates clamped to consolidation_rate, or to gas_rate while the
/// cell holds a gas.
CellServoSpec consolidation_servo(const PeriodicTriaxialParams& prm);

/// A hold at stress on a cell: the servoed axes of its spec to the spec's sigma3, the others at their fixed rates,
/// until each servoed stress is within stress_tolerance of its target and the unbalanced ratio below its tolerance.
/// Stage (a), isotropic consolidation, and each increment of a compression test (host/triax/compression_test.hpp).
class Consolidation {
 public:
  Consolidation(CellControl& cell, const PeriodicTriaxialParams& prm);
  /// A hold of `spec`, named `what` ("oedometer to 200 kPa") in its progress line and failure.
  Consolidation(CellControl& cell, const PeriodicTriaxialParams& prm, const CellServoSpec& spec,
                const std::string& what);

  StageSteps steps();
  /// After the stage: the cell's rates zeroed; "" where it converged, else why not (the error's message).
  std::string end(StageEnd& e);

 private:
  CellControl& cell_;
  PeriodicTriaxialParams prm_;
  CellServoSpec spec_;
  std::string what_;
  CellServo servo_;
  Progress progress_;
  Real err_ = 0, ratio_ = 1;
  std::array<Real, 3> s_{};
};

/// Snapshots at the configured axial strains within the test, each written once, when the strain first reaches it
/// (several passed in one step give one snapshot, labelled with the largest). None without an output.
class SnapshotSchedule {
 public:
  SnapshotSchedule(const PeriodicTriaxialParams& prm, Simulation* sim, io::Output* out);
  /// The cell is at axial strain eps.
  void at(Real eps);

 private:
  Simulation* sim_;
  io::Output* out_;
  std::vector<Real> strains_;
  std::size_t next_ = 0;
};

/// Stage (b), drained shear, on a consolidated cell: the servo of the lateral axes, the records, the snapshots.
/// Constructed at the stage's start: records the first row. `out` and `sim` (for the snapshots) may be null.
class Shear {
 public:
  Shear(CellControl& cell, PeriodicTriaxialResult& res, const GrainScales& g, io::Output* out, Simulation* sim);

  StageSteps steps();
  /// After the stage: its timing named, the cell's rates zeroed, the series flushed, the result summarised.
  void end(StageTiming timing, double wall_seconds);

 private:
  CellControl& cell_;
  PeriodicTriaxialResult& res_;
  const PeriodicTriaxialParams& prm_;
  GrainScales g_;
  io::Output* out_;
  SnapshotSchedule snapshots_;
  CellServo servo_;
  long total_;
  Progress progress_;
  Real next_record_;
  bool last_ = false;  // the step ends the test
  std::array<Real, 3> L0_{};

  void record();
};

}  // namespace dem
