#include "host/config/size_distribution.hpp"
#include "host/cli/job.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>

#include "host/engine/checkpoint.hpp"
#include "host/engine/packing.hpp"
#include "host/engine/setup.hpp"
#include "host/engine/stage_loop.hpp"
#include "host/triax/periodic_triaxial.hpp"
#include "host/triax/specimen.hpp"
#include "host/util/progress.hpp"
#include "host/triax/triaxial.hpp"

namespace dem {


namespace {

/// The `run` job's start: from its checkpoint `ckpt` where resumed (refused when that is at the step count already),
/// else its initial snapshot.
void resume_or_start(const Config& cfg, const std::string& ckpt, bool resume, Simulation& sim, io::Output& out) {
  if (!resume) {
    out.write_snapshot(take_snapshot(sim, "initial"));
    return;
  }
  resume_from(resume_checkpoint(ckpt, "run", cfg.fingerprint), sim, &out);
  if (sim.step_count() >= cfg.run.steps)
    throw std::runtime_error(ckpt + " is at step " + std::to_string(sim.step_count()) + ", the step count is " +
                             std::to_string(cfg.run.steps) + " ([run] steps or -n): nothing to continue; give -n above " +
                             std::to_string(sim.step_count()) + " to run on");
  std::printf("triaxdem: resuming %s at step %ld (t = %.6g s)\n", ckpt.c_str(), sim.step_count(), sim.time());
}

}  // namespace

int run_job(const Config& cfg, bool resume, long stop_at_step) {
  io::Output out(cfg.run.output);
  auto sim = build_simulation(cfg, true);
  out.set_series_columns({"step", "time_s", "kinetic_energy_J", "unbalanced_ratio", "contacts_ball_ball",
                          "contacts_ball_wall", "wall_force_sum_N"});
  const std::string ckpt = checkpoint_path(out.folder());
  resume_or_start(cfg, ckpt, resume, *sim, out);
  // One row of the time series; returns the unbalanced-force ratio (the stop criterion reads it too).
  auto record = [&]() {
    const auto c = sim->touching();
    Real fw = 0;
    for (const Vec3& f : sim->wall_forces()) fw += norm(f);
    const Real ratio = sim->unbalanced_ratio();
    out.append_series({static_cast<double>(sim->step_count()), sim->time(), sim->stats().kinetic, ratio,
                       static_cast<double>(c[0]), static_cast<double>(c[1]), fw});
    return std::make_pair(ratio, c[0]);
  };
  Progress progress(cfg.run.name, cfg.run.steps, sim->step_count());
  CheckpointPlan plan{ckpt, CheckpointClock(cfg.run.checkpoint_every, cfg.run.checkpoint_minutes), nullptr,
                      stop_at_step, cfg.fingerprint};
  StopSignals signals;
  StageSteps run;
  StageTiming timing;
  run.first = sim->step_count() + 1;
  run.last = cfg.run.steps;
  run.before = [&](long s) { return StepPlan{false, s % cfg.run.series_every == 0}; };
  run.after = [&](long s, bool measured) {
    if (measured) {
      const auto [ratio, ball_contacts] = record();
      char extra[96];
      std::snprintf(extra, sizeof extra, "KE %.3e J, unbalanced %.2e", sim->stats().kinetic, ratio);
      progress.update(s, extra);
      if (ratio < cfg.run.stop_ratio && ball_contacts > 0) {
        std::printf("\nunbalanced-force ratio below %g at step %ld: equilibrium reached\n", cfg.run.stop_ratio, s);
        return true;
      }
    }
    if (cfg.run.snapshot_every > 0 && s % cfg.run.snapshot_every == 0 && s != cfg.run.steps)
      out.write_snapshot(take_snapshot(*sim, "step " + std::to_string(s)));
    return false;
  };
  // The series is flushed with every checkpoint, so that a killed run's files agree with its checkpoint.
  run.checkpoint = [&](long) {
    out.flush_series();
    write_checkpoint(ckpt, checkpoint_of("run", *sim, &out, cfg.fingerprint));
  };
  run.save_blowup = [&] { save_blowup_state(out, *sim, "run", cfg.fingerprint); };
  try {
    timing = run_stage(*sim, run, &plan).timing;
    timing.name = "run";
  } catch (const BlowUp& e) {
    std::fprintf(stderr, "\ntriaxdem: %s\n  state at the blow-up saved in %s (snapshot) and %s (for inspection); "
                 "the last good checkpoint, %s, continues with --resume once the cause is fixed\n",
                 e.what(), out.folder().c_str(), blowup_path(out.folder()).c_str(), ckpt.c_str());
    return 2;
  } catch (const RunStopped& stopped) {
    std::printf("\ntriaxdem: %s\n", stopped.what());
    return stopped.code;
  }
  out.flush_series();
  out.write_snapshot(take_snapshot(*sim, "final"));
  write_checkpoint(ckpt, checkpoint_of("run", *sim, &out, cfg.fingerprint));
  progress.finish("");
  std::printf("time loop: %s\n", describe(sim->times(), sim->particles().n, sim->step_count()).c_str());
  report_timings(out.folder(), {timing});
  std::printf("output: %s/snapshots.xdmf (ParaView), %s/series.csv; checkpoint %s (more steps: --resume -n N)\n",
              out.folder().c_str(), out.folder().c_str(), ckpt.c_str());
  return 0;
}

LayerBlowUp layer_blowup(io::Output& out, const Config& cfg) {
  return [&out, &cfg](Simulation& sim) {
    save_blowup_state(out, sim, "specimen", cfg.fingerprint);
    std::fprintf(stderr, "\ntriaxdem: the specimen layer's state at the blow-up saved in %s (snapshot and %s)\n",
                 out.folder().c_str(), blowup_path(out.folder()).c_str());
  };
}

void report_timings(const std::string& folder, const std::vector<StageTiming>& stages) {
  if (stages.empty()) return;
  io::write_text_atomic(folder + "/timings.csv", timings_csv(stages));
  std::printf("timings (%s/timings.csv):\n%s", folder.c_str(), timings_table(stages).c_str());
}

int specimen_job(const Config& cfg) {
  if (!cfg.has_specimen) throw ConfigError(cfg.path + ": [specimen]: table missing (the specimen job needs it)");
  io::Output out(cfg.run.output);
  std::printf("specimen: %ld balls of %s for e = %.3f in a %.1f x %.1f mm cylinder, %ld layers\n",
              specimen_ball_count(cfg), size_text(cfg.particles).c_str(), cfg.specimen.void_ratio,
              cfg.specimen.diameter * 1e3, cfg.specimen.height * 1e3, cfg.specimen.layers);
  Specimen sp;
  StopSignals signals;
  try {
    sp = build_specimen(cfg, true, layer_blowup(out, cfg));
  } catch (const BlowUp& e) {
    std::fprintf(stderr, "\ntriaxdem: %s\n", e.what());
    return 2;
  } catch (const RunStopped& e) {
    std::fprintf(stderr, "\ntriaxdem: %s\n", e.what());
    return e.code;
  }
  write_specimen_report(out.folder(), cfg, sp);
  report_timings(out.folder(), sp.stages);
  io::Snapshot snap;
  snap.label = "specimen";
  for (std::size_t q = 0; q < sp.balls.size(); ++q) {
    for (int d = 0; d < 3; ++d) {
      snap.x.push_back(sp.balls[q].x[d]);
      snap.v.push_back(0);
      snap.w.push_back(0);
    }
    snap.radius.push_back(sp.balls[q].radius);
    snap.gid.push_back(static_cast<std::uint32_t>(q));
    snap.specimen.push_back(0);
  }
  out.write_snapshot(snap);
  std::printf("specimen: e = %.4f (target %.3f), height %.3f mm (target %.3f); layers.csv, porosity_profile.csv, "
              "snapshots.xdmf in %s\n", sp.void_ratio, cfg.specimen.void_ratio, sp.height * 1e3,
              cfg.specimen.height * 1e3, out.folder().c_str());
  // A layer stopped at its step cap is the cause of whatever follows; the void ratio is blamed only when all settled.
  require_settled(cfg, sp);
  if (sp.height > cfg.specimen.height * (1 + 1e-9))
    std::printf("specimen: WARNING: the top platen stopped above the target height: the void ratio %.3f is not "
                "reachable in this mould with these beads without squeezing them (try a larger e)\n",
                cfg.specimen.void_ratio);
  return 0;
}

namespace {
std::string g3(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", x);
  return b;
}

/// Particle-steps per second of the benchmark packing of `cfg`'s beads at about `balls` of them (between 8^3 and
/// 40^3): 4,096 beads that fit in cache ran 9 times faster than the 53,704 of the paper's specimen. The config's
/// own box may be a gas, ten times faster than a packing. Timed after the first rebuilds.
double packed_speed(const Config& cfg, long balls) {
  const int side = std::clamp(static_cast<int>(std::lround(std::cbrt(static_cast<double>(balls)))), 8, 40);
  auto probe = build_simulation(packed_lattice(cfg, side, true), false);
  probe->run(20);
  const auto t0 = std::chrono::steady_clock::now();
  const long steps = 200;
  probe->run(steps);
  Kokkos::fence();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return probe->particles().n * static_cast<double>(steps) / std::max(seconds, 1e-9);
}
}  // namespace

int check_job(const Config& cfg) {
  if (cfg.has_periodic && !cfg.has_specimen) check_periodic_config(cfg);  // what `periodic` refuses, check refuses
  auto box = build_simulation(cfg, false);
  const Real dt = box->params().integ.dt, critical = box->critical_dt();
  const std::string dt_text = g3(dt) + " s (" +
                              (cfg.solver.dt > 0 ? std::string("[solver] dt_s") : g3(cfg.solver.dt_safety) +
                                                                                      " x the critical " +
                                                                                      g3(critical) + " s") +
                              ")";
  const long job_balls = cfg.has_specimen ? specimen_ball_count(cfg) : static_cast<long>(box->particles().n);
  const double rate = packed_speed(cfg, job_balls);
  const std::string speed = g3(rate) + " particle-steps/s measured here on packed beads of this config, " +
                            std::to_string(ExecSpace().concurrency()) + " threads";
  auto estimate = [&](double balls, double steps) { return format_duration(balls * steps / rate); };
  std::printf("%s: OK\n", cfg.path.c_str());
  if (cfg.has_specimen) {
    const SpecimenConfig& sc = cfg.specimen;
    const TriaxialConfig& tc = cfg.triaxial;
    const ShearPlan shear = shear_plan(cfg, dt);
    const long records = std::lround(tc.axial_strain_end / tc.record_every);
    std::printf("a drained triaxial test (triaxdem triaxial):\n"
                "  specimen: %ld beads of %.3g mm in a %.4g x %.4g mm cylinder (target e %.3f), %ld layers, kept in "
                "../.specimens beside the output folder\n"
                "  membrane: %d x %d nodes, %.3g MPa, %.3g mm; cell pressure %.4g kPa\n"
                "  consolidation: until sigma1 is within %.2g%% of sigma3 and the unbalanced ratio below %.0e (at most "
                "%ld steps)\n"
                "  shear: inertial number %.1e (strain rate %.3g 1/s%s) to %.3g%% in %ld steps, a record every %.3g%% "
                "(%ld records)\n"
                "  time step: %s of these beads (the membrane can lower it)\n"
                "  estimate: the shear about %s at %s (no membrane, no measurements: a lower bound); the specimen "
                "(unless cached) and the consolidation come on top\n",
                job_balls, cfg.particles.diameter * 1e3, sc.diameter * 1e3, sc.height * 1e3, sc.void_ratio, sc.layers,
                tc.membrane_around, tc.membrane_segments, tc.membrane_modulus / 1e6, tc.membrane_thickness * 1e3,
                tc.sigma3 / 1e3, 100 * tc.consolidation_tol, tc.stop_ratio, tc.max_consolidation_steps,
                tc.inertial_number, shear.rate, cfg.solver.mass_scale != 1 ? ", density scaling" : "",
                100 * tc.axial_strain_end, shear.steps, 100 * tc.record_every, records, dt_text.c_str(),
                estimate(static_cast<double>(job_balls), static_cast<double>(shear.steps)).c_str(), speed.c_str());
  } else if (cfg.has_periodic) {
    const PeriodicTriaxialParams& p = cfg.periodic.triax;
    std::printf("%s (triaxdem periodic):\n"
                "  cell: %d balls of %s in %.4g x %.4g x %.4g mm, %s\n"
                "  consolidation at %.4g kPa, then shear to %.3g%% at inertial number %.1e, a record every %.3g%%\n"
                "  time step: %s\n  speed: %s\n",
                cfg.periodic.boundary == CellBoundary::walls
                    ? "a cell triaxial test between six servo-controlled walls, measured at the walls"
                    : "a periodic-cell triaxial test",
                box->particles().n, size_text(cfg.particles).c_str(), cfg.box.size[0] * 1e3, cfg.box.size[1] * 1e3,
                cfg.box.size[2] * 1e3, cfg.box.fill.c_str(), p.sigma3 / 1e3, 100 * p.target_strain,
                p.target_inertial, 100 * p.record_strain, dt_text.c_str(), speed.c_str());
  } else {
    std::printf("a box of balls (triaxdem run): %d balls, %d walls, %ld steps, about %s\n  time step: %s\n",
                box->particles().n, box->num_walls(), cfg.run.steps,
                estimate(box->particles().n, static_cast<double>(cfg.run.steps)).c_str(), dt_text.c_str());
  }
  return 0;
}

}  // namespace dem
