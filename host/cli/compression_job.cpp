/// The `compression` command: an oedometer or an isotropic compression of a config's cell into its output folder.
#include <cstdio>

#include "host/cli/cell_job.hpp"
#include "host/cli/job.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/lab/run_cost.hpp"
#include "host/triax/compression_test.hpp"
#include "host/triax/periodic_triaxial.hpp"

namespace dem {

namespace {

/// A compression test of the cell (host/triax/compression_test.hpp): its increments' table, and its record as the
/// data `calibrate --compression` reads.
class CellCompression : public CellTest {
 public:
  CellCompression(const Config& cfg, CompressionPath path, std::vector<Real> targets)
      : cfg_(cfg), path_(path), targets_(std::move(targets)) {}
  std::string kind() const override { return "compression"; }
  std::string plan_words() const override {
    return std::to_string(targets_.size()) + " " + path_name(path_) + " increments in " +
           cell_name(cfg_.periodic.boundary) + ", each held to rest";
  }
  std::pair<long, long> steps(const CellCost& cost) const override {
    return {cost.compression_steps(targets_.size(), false), cost.compression_steps(targets_.size())};
  }
  std::vector<StageTiming> run(Simulation& sim, const PeriodicTriaxialParams& tp, io::Output& out) const override {
    const CompressionResult r = run_compression_test(sim, tp, path_, targets_, &out);
    std::printf("%s: target_kPa  sigma_v_kPa  sigma_h_kPa  p_kPa  K0  eps_a_pct  eps_v_pct  void_ratio\n",
                path_name(path_));
    for (const CompressionRecord& x : r.series)
      std::printf("  %10.4g %12.4g %12.4g %7.4g %6.3f %9.4f %9.4f %10.4f\n", 1e-3 * x.target, 1e-3 * x.sigma_v,
                  1e-3 * x.sigma_h, 1e-3 * x.p, x.k0, 100 * x.eps_a, 100 * x.eps_v, x.void_ratio);
    // The record as data `calibrate --compression` reads, the material named by the run.
    io::write_text_atomic(out.folder() + "/compression_data.csv",
                          compression_csv({compression_data_of(r, cfg_.run.name, tp.sigma3)}));
    return r.stages;
  }
  void finish(const std::string& folder) const override {
    std::printf("output: %s/series.csv (a row per increment), compression_data.csv (the same as data for calibrate "
                "--compression, material \"%s\"), timings.csv\n", folder.c_str(), cfg_.run.name.c_str());
  }

 private:
  const Config& cfg_;
  CompressionPath path_;
  std::vector<Real> targets_;
};

}  // namespace

int compression_job(const Config& cfg, const std::string& path_name_in, const std::vector<double>& targets_kpa) {
  std::vector<Real> targets;
  for (double k : targets_kpa) targets.push_back(1e3 * k);
  if (targets.empty())
    for (Real f : {2, 4, 8, 4, 2}) targets.push_back(f * cfg.periodic.triax.sigma3);
  return run_cell_job(cfg, CellCompression(cfg, compression_path(path_name_in), std::move(targets)));
}

}  // namespace dem
