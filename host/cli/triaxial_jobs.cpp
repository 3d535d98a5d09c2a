/// The `triaxial` and `periodic` commands: a test from a config into its output folder, with its summary, plots
/// and the lines a user reads at the end.
#include <cstdio>
#include <filesystem>

#include "host/cli/job.hpp"
#include "host/engine/checkpoint.hpp"
#include "host/engine/setup.hpp"
#include "host/engine/stress.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/lab/run_cost.hpp"
#include "host/triax/cell_boundary.hpp"
#include "host/triax/periodic_triaxial.hpp"
#include "host/triax/specimen.hpp"
#include "host/triax/summary.hpp"
#include "host/triax/triaxial.hpp"
#include "host/util/progress.hpp"
#include "host/util/text_format.hpp"

namespace dem {

namespace {

/// The cost before the work: the engine's speed on a probe of these balls (measure_cell_cost) times the steps the
/// test plans. The specimen's layers come first, unless cached, with their own progress.
void print_triaxial_plan(const Config& cfg) {
  const MembraneCost cost(cfg);
  const Real sigma3 = cfg.triaxial.sigma3;
  std::printf("triaxial: plan: %ld balls, consolidation to %.0f kPa and shear to %.1f%% axial strain: %.3g steps, "
              "%.2g particle-steps, about %s on this machine (the specimen's layers first, unless cached)\n",
              cost.cell.balls, sigma3 / 1e3, 100 * cfg.triaxial.axial_strain_end, cost.steps(sigma3),
              cost.steps(sigma3) * static_cast<double>(cost.cell.balls), format_duration(cost.seconds(sigma3)).c_str());
}

}  // namespace

void print_cell_plan(const Config& cfg, const std::string& command, const std::string& test, const CellCost& cost,
                     long low_steps, long high_steps) {
  const Real prep = cfg.periodic.prep_mu_s >= 0 ? cfg.periodic.prep_mu_s : cfg.ball.mu_s;
  const PackingCost at = packing_cost_at(prep);
  const double packing = static_cast<double>(cost.packing_steps), balls = static_cast<double>(cost.balls);
  const double step_s = 1e-9 * cost.ns_per_particle_step * balls;
  const double low = at.low * packing + static_cast<double>(low_steps),
               high = at.high * packing + static_cast<double>(high_steps);
  std::printf("%s: plan: %ld balls, a packing (preparation friction %.3g: %.3g to %.3g steps), consolidation to %.0f "
              "kPa and %s (%ld to %ld steps%s): %.2g to %.2g particle-steps, about %s to %s on this machine\n",
              command.c_str(), cost.balls, prep, at.low * packing, at.high * packing,
              cfg.periodic.triax.sigma3 / 1e3, test.c_str(), low_steps, high_steps,
              cost.resettles() ? ", the balls sliding on without friction: the consolidation settles them again" : "",
              low * balls, high * balls, format_duration(low * step_s).c_str(), format_duration(high * step_s).c_str());
}

namespace {

/// The same for a cell's test: its packing (at its preparation friction's cost, packing_cost_at), consolidation and
/// shear, from a probe of its balls. A config the cell test refuses is refused first, with its own words.
void print_periodic_plan(const Config& cfg) {
  check_periodic_config(cfg);
  const CellCost cost = measure_cell_cost(cfg);
  const Real sigma3 = cfg.periodic.triax.sigma3;
  print_cell_plan(cfg, cfg.periodic.boundary == CellBoundary::walls ? "walls" : "periodic",
                  fmt("shear to %.1f%% axial strain", 100 * cfg.periodic.triax.target_strain), cost,
                  cost.run_steps(sigma3, false), cost.run_steps(sigma3));
}

}  // namespace

int triaxial_job(const Config& cfg, bool resume, long stop_at_step) {
  if (!cfg.has_specimen) throw ConfigError(cfg.path + ": [specimen]: table missing (the triaxial job needs it)");
  io::Output out(cfg.run.output);
  CheckpointPlan plan{checkpoint_path(out.folder()), CheckpointClock(cfg.run.checkpoint_every,
                      cfg.run.checkpoint_minutes), nullptr, stop_at_step, cfg.fingerprint};
  Checkpoint from;
  if (resume) {
    from = resume_checkpoint(plan.path, "triaxial", cfg.fingerprint);
    plan.from = &from;
  }
  StopSignals signals;
  try {
    print_triaxial_plan(cfg);
    // Specimens are shared through a cache beside the output folder; each run keeps a copy, which a resume reads first.
    const Specimen sp = cached_specimen(cfg, (std::filesystem::path(out.folder()).parent_path() / ".specimens").string(),
                                        true, out.folder() + "/specimen.csv");
    std::printf("specimen: %zu balls, e = %.4f, height %.3f mm (layers.csv, porosity_profile.csv)\n",
                sp.balls.size(), sp.void_ratio, sp.height * 1e3);
    write_specimen_report(out.folder(), cfg, sp);
    const TriaxialResult r = run_triaxial(cfg, sp, &out, true, &plan);
    const Real q_highest = r.records.empty() ? 0 : r.records[r.highest_record].q;
    std::printf("\nresult: q_peak %.1f kPa at eps_a %.2f%% (moving mean over +-%.2f%% strain; highest record %.1f kPa), "
                "peak friction angle %.1f deg, q at %.0f%% %.1f kPa (mean over the last %.0f%%), max dilatancy %.3f, "
                "wall time %s\n",
                r.q_peak / 1e3, 100 * r.eps_a_peak, 100 * kSmoothHalfWidth, q_highest / 1e3, r.phi_peak_deg,
                100 * cfg.triaxial.axial_strain_end, r.q_end / 1e3, 100 * kEndWindow, r.max_dilatancy,
                format_duration(r.wall_seconds).c_str());
    if (r.escaped > 0) std::printf("WARNING: %d balls ended outside the membrane\n", r.escaped);
    if (!r.micro.empty()) {
      // The stress-force-fabric relation beside the boundary's q/p (p = sigma3 + q/3) at the highest record,
      // where the run wrote its micro_*_peak files (the smoothed peak is known only at the end).
      const std::size_t k = r.highest_record;
      const MicroRow& m = r.micro[k];
      std::printf("at the highest record (micro_*_peak.csv): q/p %.3f at the boundary, %.3f from the contacts "
                  "(Love-Weber), %.3f from the stress-force-fabric relation, with a_c %.3f, a_n %.3f, a_t %.3f; "
                  "Z %.2f\n",
                  r.records[k].q / triaxial_mean_stress(cfg.triaxial.sigma3, r.records[k].q), m.q_over_p, m.q_over_p_sff, m.all.a_c,
                  m.all.a_n, m.all.a_t, m.z.z);
    }
    std::printf("time loop (consolidation and shear): %s; measurements and output %.1f s\n",
                describe(r.times, r.balls, r.steps).c_str(), r.wall_seconds - r.times.loop());
    std::vector<StageTiming> stages = sp.stages;
    stages.insert(stages.end(), r.stages.begin(), r.stages.end());
    report_timings(out.folder(), stages);
    write_summary(out.folder(), summary_of(cfg, r, static_cast<long>(sp.balls.size())));
    std::printf("output: %s/series.csv, summary.csv, snapshots.xdmf (ParaView: balls and membrane)\n",
                out.folder().c_str());
    run_plot_script("plot_triaxial.py", {out.folder(), "--title", cfg.run.name});
    if (cfg.micro.enabled) run_plot_script("plot_micro.py", {out.folder()});
  } catch (const BlowUp& e) {
    std::fprintf(stderr, "\ntriaxdem: %s\n", e.what());
    return 2;
  } catch (const RunStopped& e) {
    std::printf("\ntriaxdem: %s\n", e.what());
    return e.code;
  }
  return 0;
}

int cell_blowup(io::Output& out, Simulation* sim, const std::string& kind, const Config& cfg, const BlowUp& e) {
  out.flush_series();
  if (sim) {
    out.write_snapshot(take_snapshot(*sim, "blow-up"));
    write_checkpoint(blowup_path(out.folder()), checkpoint_of(kind, *sim, &out, cfg.fingerprint));
  }
  std::fprintf(stderr, "\ntriaxdem: %s\n  state at the blow-up saved in %s (snapshot and %s)\n", e.what(),
               out.folder().c_str(), blowup_path(out.folder()).c_str());
  return 2;
}

int run_periodic_job(const Config& cfg) {
  std::vector<BallSpec> balls;
  std::array<Real, 3> cell{};
  print_periodic_plan(cfg);
  prepare_periodic_specimen(cfg, balls, cell, true);
  PeriodicTriaxialParams tp = cfg.periodic.triax;
  tp.name = cfg.run.name;
  io::Output out(cfg.run.output);
  std::unique_ptr<Simulation> sim;
  std::vector<StageTiming> timings;
  auto announce = [&](const char* what) {
    const std::array<Real, 3> l = cell_lengths(*sim);
    std::printf("triaxdem: %s: %zu balls in %s %.2f x %.2f x %.2f mm; critical dt %.3e s, dt %.3e s\n", what,
                balls.size(), cell_name(cfg.periodic.boundary), 1e3 * l[0], 1e3 * l[1], 1e3 * l[2],
                sim->critical_dt(), sim->params().integ.dt);
    if (cfg.solver.mass_scale != 1)
      std::printf("triaxdem: DENSITY SCALING x%g is on: inertia is not physical (quasi-static runs only)\n",
                  cfg.solver.mass_scale);
  };
  try {
    sim = make_periodic_simulation(balls, cell, cfg.ball, cfg.solver, cfg.periodic.boundary);
    announce("test");
    const PeriodicTriaxialResult r = run_periodic_triaxial(*sim, tp, &out);
    timings = r.stages;
    write_summary(out.folder(), summary_of(cfg, r, static_cast<long>(balls.size())));
  } catch (const BlowUp& e) {
    return cell_blowup(out, sim.get(), "periodic", cfg, e);
  }
  std::printf("time loop (test): %s\n", describe(sim->times(), sim->particles().n, sim->step_count()).c_str());
  report_timings(out.folder(), timings);
  std::printf("output: %s/series.csv, summary.csv, snapshots.xdmf\n", out.folder().c_str());
  run_plot_script("plot_triaxial.py", {out.folder(), "--title", cfg.run.name});
  return 0;
}

}  // namespace dem
