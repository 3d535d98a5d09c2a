/// The `triaxial` and `periodic` commands: a test from a config into its output folder, with its summary, plots
/// and the lines a user reads at the end.
#include <cstdio>
#include <filesystem>

#include "host/cli/cell_job.hpp"
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
                                        true, out.folder() + "/specimen.csv", layer_blowup(out, cfg));
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

namespace {

/// The drained triaxial test of the cell (host/triax/periodic_triaxial.hpp): consolidation and shear, its summary.
class CellTriaxial : public CellTest {
 public:
  explicit CellTriaxial(const Config& cfg) : cfg_(cfg) {}
  std::string kind() const override {
    return cfg_.periodic.boundary == CellBoundary::walls ? "walls" : "periodic";
  }
  std::string plan_words() const override {
    return fmt("shear to %.1f%% axial strain", 100 * cfg_.periodic.triax.target_strain);
  }
  std::pair<long, long> steps(const CellCost& cost) const override {
    const Real sigma3 = cfg_.periodic.triax.sigma3;
    return {cost.run_steps(sigma3, false), cost.run_steps(sigma3)};
  }
  std::vector<StageTiming> run(Simulation& sim, const PeriodicTriaxialParams& tp, io::Output& out) const override {
    const PeriodicTriaxialResult r = run_periodic_triaxial(sim, tp, &out);
    write_summary(out.folder(), summary_of(cfg_, r, static_cast<long>(sim.particles().n)));
    return r.stages;
  }
  void finish(const std::string& folder) const override {
    std::printf("output: %s/series.csv, summary.csv, snapshots.xdmf\n", folder.c_str());
    run_plot_script("plot_triaxial.py", {folder, "--title", cfg_.run.name});
  }

 private:
  const Config& cfg_;
};

}  // namespace

int run_periodic_job(const Config& cfg) { return run_cell_job(cfg, CellTriaxial(cfg)); }

}  // namespace dem
