/// The `compression` command: an oedometer or an isotropic compression of a config's cell into its output folder.
#include <cstdio>

#include "host/cli/job.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/lab/run_cost.hpp"
#include "host/triax/compression_test.hpp"
#include "host/triax/periodic_triaxial.hpp"
#include "host/util/progress.hpp"

namespace dem {

int compression_job(const Config& cfg, const std::string& path_name_in, const std::vector<double>& targets_kpa) {
  check_periodic_config(cfg);
  const CompressionPath path = compression_path(path_name_in);
  PeriodicTriaxialParams tp = cfg.periodic.triax;
  tp.name = cfg.run.name;
  std::vector<Real> targets;
  for (double k : targets_kpa) targets.push_back(1e3 * k);
  if (targets.empty())
    for (Real f : {2, 4, 8, 4, 2}) targets.push_back(f * tp.sigma3);
  const CellCost cost = measure_cell_cost(cfg);
  print_cell_plan(cfg, "compression", std::to_string(targets.size()) + " " + dem::path_name(path) +
                  " increments in " + cell_name(cfg.periodic.boundary) + ", each held to rest", cost,
                  cost.compression_steps(targets.size(), false), cost.compression_steps(targets.size()));
  std::vector<BallSpec> balls;
  std::array<Real, 3> cell{};
  prepare_periodic_specimen(cfg, balls, cell, true);
  io::Output out(cfg.run.output);
  std::unique_ptr<Simulation> sim;
  try {
    sim = make_periodic_simulation(balls, cell, cfg.ball, cfg.solver, cfg.periodic.boundary);
    const CompressionResult r = run_compression_test(*sim, tp, path, targets, &out);
    std::printf("%s: target_kPa  sigma_v_kPa  sigma_h_kPa  p_kPa  K0  eps_a_pct  eps_v_pct  void_ratio\n",
                dem::path_name(path));
    for (const CompressionRecord& x : r.series)
      std::printf("  %10.4g %12.4g %12.4g %7.4g %6.3f %9.4f %9.4f %10.4f\n", 1e-3 * x.target, 1e-3 * x.sigma_v,
                  1e-3 * x.sigma_h, 1e-3 * x.p, x.k0, 100 * x.eps_a, 100 * x.eps_v, x.void_ratio);
    report_timings(out.folder(), r.stages);
    // The record as data `calibrate --compression` reads, the material named by the run.
    io::write_text_atomic(out.folder() + "/compression_data.csv",
                          compression_csv({compression_data_of(r, cfg.run.name, tp.sigma3)}));
  } catch (const BlowUp& e) {
    return cell_blowup(out, sim.get(), "compression", cfg, e);
  }
  std::printf("time loop: %s\noutput: %s/series.csv (a row per increment), compression_data.csv (the same as "
              "data for calibrate --compression, material \"%s\"), timings.csv\n",
              describe(sim->times(), sim->particles().n, sim->step_count()).c_str(), out.folder().c_str(),
              cfg.run.name.c_str());
  return 0;
}

}  // namespace dem
