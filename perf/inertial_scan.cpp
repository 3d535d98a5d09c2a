/// How fast a calibration's periodic cell may shear: the same specimens (same packing seeds, so each difference is
/// paired and the specimens' own scatter cancels) sheared at each inertial number listed, and each curve feature
/// (q / sigma3 at its peak and q / sigma3 and eps_v at a few strains) compared with the first rate's. A rate is
/// quasi-static enough where every feature's mean moves by less than kEnsembleRatioGoal of the specimens' scatter: the
/// shift then adds at most a quarter to the variance the misfit already counts, as an ensemble's standard error may.
///
///   ./build/perf/inertial_scan --specimens 8 --pressures 100,300 -j 2 -o runs/inertial_scan.csv
///
/// With --preparation-emod the levels are the stiffness the specimens are prepared with instead ([periodic] prep_mu_s
/// or prep_mu_r must give a preparation stage), each tested at the config's law and rate: whether a calibration whose
/// emod is free, on cells prepared once at the base's, is biased against data prepared by the material itself. Other
/// stiffnesses pack other specimens from the same seeds, so the pairs are hardly paired; the shift's standard error
/// (shift_se, over the specimens) says what the specimens resolve.
///
/// Prints per level the cost of a run and the largest shift in units of the scatter, and writes one CSV row per level,
/// pressure and feature.
#include <CLI/CLI.hpp>
#include <Kokkos_Core.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "host/config/config.hpp"
#include "host/data/curve_reading.hpp"
#include "host/fit/misfit.hpp"
#include "host/lab/periodic_lab.hpp"
#include "host/util/text_format.hpp"

using namespace dem;

namespace {

struct CurvePoint {
  const char* quantity;
  Real strain;
};

/// The value of a curve point of a simulated test: q in units of sigma3 (at its peak, q_peak, where the strain is 0),
/// eps_v as it is.
Real feature_value(const TriaxialTest& t, const CurvePoint& f) {
  if (f.quantity[0] != 'q') return curve_value(t.eps_a, t.eps_v, f.strain);
  return (f.strain > 0 ? curve_value(t.eps_a, t.q, f.strain) : t.q_peak) / t.sigma3;
}

Real mean(const std::vector<Real>& v) {
  Real s = 0;
  for (Real x : v) s += x;
  return s / static_cast<Real>(v.size());
}

Real sd(const std::vector<Real>& v) {
  const Real m = mean(v);
  Real s = 0;
  for (Real x : v) s += (x - m) * (x - m);
  return v.size() > 1 ? std::sqrt(s / static_cast<Real>(v.size() - 1)) : 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("triaxdem: the periodic cell's curves against its inertial number");
  std::string config = std::string(TRIAXDEM_SOURCE_DIR) + "/configs/calibration/base.toml";
  std::string out = "inertial_scan.csv";
  int specimens = 8, workers = 2;
  std::vector<double> pressures{100, 300}, inertials{5e-4, 1e-3, 2e-3, 4e-3, 8e-3}, prep_emods;
  double strain_pct = 0;
  app.add_option("--config", config, "base config of the periodic cell")->check(CLI::ExistingFile);
  app.add_option("--specimens", specimens, "specimens (packing seeds [run] seed on)")->check(CLI::Range(2, 64));
  app.add_option("--pressures", pressures, "confining pressures, kPa")->delimiter(',');
  app.add_option("--inertial", inertials, "inertial numbers, the first the reference")->delimiter(',');
  app.add_option("--preparation-emod", prep_emods, "instead: the specimens' preparation stiffness (Pa), the first the "
                 "reference, each tested at the config's law and rate")->delimiter(',');
  app.add_option("--axial-strain-pct", strain_pct, "end every test here instead of the config's")
      ->check(CLI::Range(0.5, 30.0));
  app.add_option("-j,--jobs", workers, "simulator runs at once, one thread each");
  app.add_option("-o,--output", out, "CSV of the comparisons");
  CLI11_PARSE(app, argc, argv);
  prepare_parallel_runs(workers);
  Kokkos::ScopeGuard guard(argc, argv);

  Config cfg = load_config(config);
  if (strain_pct > 0) cfg.periodic.triax.target_strain = strain_pct / 100;
  cfg.periodic.triax.axial_rate = 0;
  cfg.periodic.triax.allow_high_inertial = true;
  const bool preparation = !prep_emods.empty();
  if (preparation && cfg.periodic.prep_mu_s < 0 && cfg.periodic.prep_mu_r < 0) {
    std::fprintf(stderr, "inertial_scan: %s: --preparation-emod needs a preparation stage ([periodic] prep_mu_s or "
                 "prep_mu_r, >= 0): without one the test's own consolidation packs each specimen at the test's law\n",
                 config.c_str());
    return 2;
  }
  const std::vector<double>& levels = preparation ? prep_emods : inertials;
  const char* level_name = preparation ? "preparation_emod_Pa" : "inertial";
  std::vector<CurvePoint> features{{"q", 0}};  // the peak
  for (const char* q : {"q", "eps_v"})
    for (Real e : {0.001, 0.005, 0.01, 0.02, 0.04, 0.08, 0.15})
      if (e <= cfg.periodic.triax.target_strain * (1 - 1e-9)) features.push_back({q, e});
  std::vector<TriaxialTest> like;
  for (double p : pressures) {
    TriaxialTest t;
    t.material = "scan";
    t.sigma3 = 1e3 * p;
    like.push_back(t);
  }

  std::vector<Ensemble> runs;
  std::vector<double> seconds;
  for (double level : levels) {
    Config c = cfg;
    if (preparation) c.ball.emod = level;  // the preparation's law: the tests run at the config's (model_of(cfg))
    else c.periodic.triax.target_inertial = level;
    PeriodicLab lab(c, false, specimens, c.run.seed, specimens, workers);
    lab.set_progress(std::string(preparation ? "preparation emod " : "inertial number ") + fmt("%g", level));
    runs.push_back(lab.run_ensemble(model_of(preparation ? cfg : c), like, true));
    seconds.push_back(lab.seconds() / std::max(1L, lab.runs()));
  }

  std::ofstream csv(out);
  csv << level_name << ",sigma3_kPa,feature,strain_pct,reference_mean,reference_sd,mean_shift,shift_sd,"
         "shift_over_scatter,shift_se_over_scatter\n";
  std::printf("\n%10s %10s %14s  %s\n", preparation ? "prep emod" : "inertial", "s a run", "largest shift",
              "(in units of one specimen's scatter at the reference level, +- its standard error; below 0.5 the "
              "shift adds at most a quarter to the variance the misfit counts)");
  for (std::size_t r = 0; r < levels.size(); ++r) {
    Real worst = 0, worst_se = 0;
    std::string where;
    for (std::size_t k = 0; k < like.size(); ++k)
      for (const CurvePoint& f : features) {
        std::vector<Real> ref, diff;
        for (int s = 0; s < specimens; ++s) {
          const Real a = feature_value(runs[0][k][s], f), b = feature_value(runs[r][k][s], f);
          if (!std::isfinite(a) || !std::isfinite(b)) continue;
          ref.push_back(a);
          diff.push_back(b - a);
        }
        if (ref.size() < 2) continue;
        const Real scatter = sd(ref), shift = mean(diff);
        const Real ratio = scatter > 0 ? std::fabs(shift) / scatter : 0;
        const Real se = scatter > 0 ? sd(diff) / std::sqrt(static_cast<Real>(diff.size())) / scatter : 0;
        csv << levels[r] << "," << pressures[k] << "," << f.quantity << "," << 100 * f.strain << "," << mean(ref)
            << "," << scatter << "," << shift << "," << sd(diff) << "," << ratio << "," << se << "\n";
        if (ratio > worst) {
          worst = ratio, worst_se = se;
          char w[96];
          if (f.strain > 0) std::snprintf(w, sizeof w, "%s at %.1f%%, %g kPa", f.quantity, 100 * f.strain, pressures[k]);
          else std::snprintf(w, sizeof w, "q_peak, %g kPa", pressures[k]);
          where = w;
        }
      }
    std::printf("%10.2g %10.2f %8.2f +-%4.2f  %s%s\n", levels[r], seconds[r], worst, worst_se, where.c_str(),
                r == 0 ? " (the reference)" : worst < kEnsembleRatioGoal ? "" : "  ABOVE 0.5");
  }
  std::printf("rows: %s\n", out.c_str());
  return 0;
}
