#include "host/triax/triaxial.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <tuple>

#include "host/engine/membrane_mesh.hpp"
#include "host/engine/setup.hpp"
#include "host/engine/stage_loop.hpp"
#include "host/engine/stress.hpp"
#include "host/data/measured.hpp"
#include "host/triax/q_columns.hpp"
#include "host/triax/shear_record.hpp"
#include "host/triax/micro_report.hpp"
#include "host/util/progress.hpp"
#include "kernels/motion/wall_servo.hpp"
#include "host/triax/summary.hpp"
#include "host/triax/triaxial_cell.hpp"
#include "host/triax/triaxial_measure.hpp"
#include "host/triax/triaxial_state.hpp"
#include "host/engine/simulation.hpp"

namespace dem {

namespace {

/// Isotropic consolidation from the state in `st` (a resumed run's, or step 0): cell pressure on the membrane, stress
/// servo on the top platen, until the platen's stress and the unbalanced ratio settle; then `st` moves to shear with
/// the consolidated height, volumes and void ratio. `stage` comes with what both stages of the test do alike
/// (checkpoints, the blow-up's save); `plan` may be null.
StageTiming consolidate(const Config& cfg, const Specimen& sp, Cell& cell, Stage& st, bool verbose, StageSteps stage,
                        CheckpointPlan* plan) {
  const TriaxialConfig& tc = cfg.triaxial;
  Simulation& sim = *cell.sim;
  const Real dt = sim.params().integ.dt;
  // Isotropic consolidation: cell pressure on the membrane, stress servo on the top platen.
  StressServo servo;
  servo.target = tc.sigma3;
  servo.area = cell.area;
  servo.v_max = 0.05 * sp.height / (2000 * dt);  // at most 5% of the height in 2000 steps
  Progress cons("consolidation (ETA to the step cap)", tc.max_consolidation_steps, st.step);
  Real top = 0, bottom = 0;  // the platens' stresses before the step
  stage.first = st.step + 1;
  stage.last = tc.max_consolidation_steps;
  // The servo steers the top platen and its ring of membrane nodes on the device, before each step.
  WallServoSpec on_top;
  on_top.servo = servo;
  on_top.wall = kTopPlaten;
  on_top.axis = 2;
  on_top.sign = -1;  // down, into the specimen
  on_top.kn = cell.kn_wall;
  on_top.tied = cell.membrane.ring_top;
  bool servoing = false;
  stage.before = [&](long n) {
    if (!servoing) sim.set_wall_servo(on_top);
    servoing = true;
    const bool measured = n % 200 == 0;
    // What the servo reads before a measured step, for the stage's check after it.
    if (measured) std::tie(top, bottom) = platen_stresses(cell, sim.wall_loads(false).force);
    return StepPlan{false, measured};
  };
  stage.after = [&](long n, bool measured) {
    if (measured) {
      const Real ratio = sim.unbalanced_ratio();
      // The servo holds the top platen; the bottom one differs by what the membrane carries through
      // friction and its own axial stiffness, so only the controlled stress decides.
      const Real err = std::fabs(top - tc.sigma3) / tc.sigma3;
      if (verbose) {
        char extra[96];
        std::snprintf(extra, sizeof extra, "sigma_top %.1f kPa, sigma_bottom %.1f kPa, unbalanced %.1e",
                      top / 1e3, bottom / 1e3, ratio);
        cons.update(n, extra);
      }
      if (err < tc.consolidation_tol && ratio < tc.stop_ratio) return true;
    }
    st.step = n;
    return false;
  };
  const StageEnd end = run_stage(sim, stage, plan);
  sim.end_wall_servo();
  if (!end.done)
    throw ConfigError(cfg.path + ": [triaxial] max_consolidation_steps: consolidation to " +
                      std::to_string(tc.sigma3 / 1e3) + " kPa did not settle within " +
                      std::to_string(tc.max_consolidation_steps) + " steps");
  st.shear = true;
  st.step = 0;
  st.consolidation_steps = end.step;
  st.h0 = sim.wall_point(kTopPlaten).z;
  st.v0 = specimen_volume(cell);
  st.v0_envelope = envelope_volume(sim, st.h0, cell.mean_radius, tc.membrane_segments);
  st.void_ratio = st.v0 / cell.solid_volume - 1;
  if (verbose)
    std::printf("\nconsolidated at %.0f kPa: e = %.4f, height %.3f mm after %ld steps\n", tc.sigma3 / 1e3,
                st.void_ratio, st.h0 * 1e3, st.consolidation_steps);
  StageTiming timing = end.timing;
  timing.name = "consolidation";
  return timing;
}

/// What a blow-up leaves for inspection: the curve so far, a snapshot of balls, membrane and contacts, and the
/// state (with a checkpoint plan) in blowup.h5.
void save_blowup(Simulation& sim, const Cell& cell, io::Output& out, const Stage& st, const TriaxialResult& res,
                 const CheckpointPlan* plan) {
  out.flush_series();
  const io::SurfaceSnapshot surface = membrane_surface(cell.membrane);
  const io::ContactTable contacts = contact_table(contact_set(sim));
  out.write_snapshot(take_snapshot(sim, "blow-up"), &surface, &contacts);
  if (plan) save_triaxial(blowup_path(out.folder()), sim, &out, st, res, plan->config);
  std::fprintf(stderr, "triaxdem: state at the blow-up saved in %s (snapshots.xdmf, last entry; %s)\n",
               out.folder().c_str(), blowup_path(out.folder()).c_str());
}

/// The result's curve values from its records, its highest record, the balls that left the membrane, and the
/// run's times and counts.
void finish_result(const Cell& cell, Real sigma3, double wall_seconds, TriaxialResult& res) {
  Simulation& sim = *cell.sim;
  if (!res.records.empty()) {
    take_curve_values(res, summarised(res.records, sigma3));
    res.highest_record = static_cast<std::size_t>(
        std::max_element(res.records.begin(), res.records.end(),
                         [](const TriaxialRecord& a, const TriaxialRecord& b) { return a.q < b.q; }) -
        res.records.begin());
  }
  res.escaped = count_escaped(sim, cell.membrane, sim.wall_point(kTopPlaten).z);
  res.wall_seconds = wall_seconds;
  res.times = sim.times();
  res.steps = sim.step_count();
  res.balls = sim.particles().n;
}

}  // namespace

ShearPlan shear_plan(const Config& cfg, Real dt) {
  const TriaxialConfig& tc = cfg.triaxial;
  // Constant platen speed from the inertial number (density scaling counts in rho).
  const Real rho = cfg.particles.density * cfg.solver.mass_scale;
  ShearPlan p;
  p.rate = tc.inertial_number / (cfg.particles.diameter * std::sqrt(rho / tc.sigma3));
  // The platen speeds up linearly over the steps of kRampStrain at full rate (the strain lost to the ramp,
  // half of that, is added at the end). Started at full speed at once, it sends a stress wave that the top
  // platen reads as a peak before the bottom one feels any load: 160 kPa at 0.1% strain against a
  // quasi-static plateau of 140 kPa in the full-scale S-1 case at 100 kPa.
  constexpr Real kRampStrain = 0.005;
  p.ramp = std::max(1L, std::lround(kRampStrain / (p.rate * dt)));
  p.steps = static_cast<long>(std::ceil(tc.axial_strain_end / (p.rate * dt))) + p.ramp / 2;
  return p;
}

Real TriaxialRecord::*q_field(QMeasure m) {
  const QColumn* c = q_column(m);
  return c ? c->record : &TriaxialRecord::q;
}

TriaxialTest curves_of(const TriaxialResult& r, Real TriaxialRecord::*q, Real sigma3) {
  std::vector<TriaxialRecord> rows = r.records;
  for (TriaxialRecord& x : rows) x.q = x.*q;
  return summarised(rows, sigma3);
}

TriaxialResult run_triaxial(const Config& cfg, const Specimen& sp, io::Output* out, bool verbose,
                            CheckpointPlan* plan) {
  const auto t0 = std::chrono::steady_clock::now();
  const TriaxialConfig& tc = cfg.triaxial;
  Cell cell = make_cell(cfg, sp);
  Simulation& sim = *cell.sim;
  const Real dt = sim.params().integ.dt;
  TriaxialResult res;
  const MicroConfig& mc = cfg.micro;
  if (out) out->set_series_columns(series_columns(mc));
  Stage st;
  // Wall time of the whole test: a resumed run adds what the segments before it took.
  double wall_before = 0;
  auto elapsed = [&] { return wall_before + std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  if (plan && plan->from) {
    restore_triaxial(*plan->from, plan->path, sim, out, st, res);
    wall_before = res.wall_seconds;
    if (verbose)
      std::printf("triaxial: resuming %s at step %ld (%s)\n", plan->path.c_str(), sim.step_count(),
                  st.shear ? "shear" : "consolidation");
  }
  // What both stages do alike: a checkpoint of the test's stage and curve when due; on a blow-up, the state it
  // happened in (balls, membrane, contacts) and the curve so far.
  StageSteps shared;
  RecordWork work(mc, cell.mean_radius, tc.membrane_segments, out ? out->folder() : std::string());
  shared.checkpoint = [&](long) {
    work.finish();
    if (out) out->flush_series();
    res.wall_seconds = elapsed();
    save_triaxial(plan->path, sim, out, st, res, plan->config);
  };
  if (out) shared.save_blowup = [&] { work.finish(); save_blowup(sim, cell, *out, st, res, plan); };
  if (!st.shear) res.stages.push_back(consolidate(cfg, sp, cell, st, verbose, shared, plan));
  res.consolidation_steps = st.consolidation_steps;
  res.void_ratio_consolidated = st.void_ratio;
  const Real h0 = st.h0, v0 = st.v0, v0_envelope = st.v0_envelope;

  const ShearPlan plan_of_shear = shear_plan(cfg, dt);
  res.shear_rate = plan_of_shear.rate;
  res.inertial_number = tc.inertial_number;
  const long ramp = plan_of_shear.ramp, steps = plan_of_shear.steps;
  if (verbose && st.step == 0)
    std::printf("shear: strain rate %.3g 1/s (inertial number %.1e%s), %ld steps to %.0f%%\n", res.shear_rate,
                tc.inertial_number, cfg.solver.mass_scale != 1 ? ", with density scaling" : "", steps,
                tc.axial_strain_end * 100);
  const std::array<Real, kSnapshotStrains> snaps = {0.0, 0.01, 0.05, tc.axial_strain_end};
  Progress shear("shear", steps, st.step);
  StateCopies copies;
  const ShearRecorder recorder{cfg, cell, st, res, out, h0, v0, v0_envelope, snaps, shear, copies, work, verbose};
  // Before step k + 1, the state step k left: its record and snapshot where due (the last state's too), then the
  // platen's control. A checkpoint follows each step, before the record of the state it left (a resumed run
  // takes that record).
  StageSteps shear_stage = shared;
  shear_stage.first = st.step + 1;
  shear_stage.last = steps + 1;
  shear_stage.before = [&](long n) {
    const long k = n - 1;
    observe_shear(recorder, k, k == steps);
    if (k == steps) return StepPlan{true, false};
    if (k < ramp) set_top_velocity(cell, -res.shear_rate * h0 * static_cast<Real>(k + 1) / ramp);
    if (tc.damping_about_flow) {  // the bottom platen rests at z = 0: the flow is v_z = v_top z / h
      const Real h = sim.wall_point(kTopPlaten).z;
      sim.set_damping_flow(Vec3(0, 0, sim.wall_velocity(kTopPlaten).z / h), Vec3());
    }
    // The unbalanced ratio and kinetic energy cost a pass: measured on the steps before a record only.
    const Real eps_next = (h0 - sim.wall_point(kTopPlaten).z) / h0 + res.shear_rate * dt;
    return StepPlan{false, eps_next >= st.next_record - 1e-12 || k + 1 == steps};
  };
  shear_stage.after = [&](long n, bool) {
    st.step = n;
    return false;
  };
  res.stages.push_back(run_stage(sim, shear_stage, plan).timing);
  res.stages.back().name = "shear";
  work.finish();
  if (out) out->flush_series();
  finish_result(cell, tc.sigma3, elapsed(), res);
  return res;
}


}  // namespace dem
