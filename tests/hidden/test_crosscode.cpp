/// Diagnosis of curves made by another DEM code (tests/data/crosscode/, YADE 2023.02a, see its README): data the
/// simulator did not make, from a larger cell (1000-1500 balls against 150), another preparation, rate and
/// rolling law. Linear contacts: no extension may be named, and on a cell of 600 balls (a long case) the
/// calibration's joint 95% region must hold the generating mu_s 0.4, mu_r 0.04. Hertz-Mindlin contacts: the diagnosis must name hertz. The base configs hold what a user knows of the other code's set-up and generic
/// friction to start from; the data's void ratio sets the preparation, as `triaxdem diagnose` does.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "host/fit/calibrate.hpp"
#include "host/config/config.hpp"
#include "host/fit/diagnose.hpp"
#include "host/data/measured.hpp"
#include "host/fit/prediction.hpp"
#include "host/fit/two_fidelity.hpp"
#include "host/lab/periodic_lab.hpp"
#include "host/lab/wall_layer.hpp"

using namespace dem;

namespace {

struct CrossCase {
  std::string name, data, config, verdict;
  int cell_factor = 1;  ///< the base config's cell with this many times its balls (larger_cell)
  bool region = false;  ///< the generating friction must lie in the joint 95% region whatever the cell
};

void PrintTo(const CrossCase& c, std::ostream* os) { *os << c.name; }
std::string case_name(const ::testing::TestParamInfo<CrossCase>& i) { return i.param.name; }

class CrossCode : public ::testing::TestWithParam<CrossCase> {};

TEST_P(CrossCode, DiagnosisOfAnotherCodesCurves) {
  const CrossCase c = GetParam();
  const std::string dir = std::string(TRIAXDEM_SOURCE_DIR) + "/tests/data/crosscode/";
  const MeasuredData data = load_measured(dir + c.data);
  StateMatch state;
  const Config loaded = load_config(dir + c.config);
  const Config cell = larger_cell(reference_cell(loaded, ""), c.cell_factor);
  const Config cfg = matched_state(cell, data.tests, state, false, match_plan(cell, 2));
  ASSERT_EQ(state.tests, 3);
  // The preparation's reach in void ratio is coarse on the mean of two small specimens; 0.02 is about the spread
  // between specimens of 150 balls at one friction.
  EXPECT_NEAR(state.reached, state.target, 0.02) << "preparation friction " << state.prep_mu_s;
  PeriodicLab lab(cfg, false, 2);
  const Model base = model_of(cfg);
  const Misfit misfit = measure_misfit(lab, base, data.tests, NoiseOptions());
  const Diagnosis dg =
      diagnose(lab, base, {free_param("mu_s", base), free_param("mu_r", base)}, data.tests, misfit, false);
  std::printf("crosscode %s: verdict %s. %s\n  mu_s %.4g [%.4g, %.4g], mu_r %.4g [%.4g, %.4g], correlation %.2f\n",
              c.name.c_str(), dg.verdict.c_str(), dg.explanation.c_str(), dg.base.values[0],
              dg.base.interval[0].first, dg.base.interval[0].second, dg.base.values[1], dg.base.interval[1].first,
              dg.base.interval[1].second, dg.base.correlation[0][1]);
  for (const ExtensionFit& f : dg.fits) std::printf("  %s: %s\n", f.ext.name.c_str(), f.reason.c_str());
  EXPECT_EQ(dg.verdict, c.verdict) << dg.explanation;
  if (c.verdict == "none") {
    // No physical name, but the report states the difference it found, as the generic shape that fits it best.
    EXPECT_NE(dg.explanation.find("generic discrepancy"), std::string::npos) << dg.explanation;
    // The generating friction must lie inside the reported joint 95% region. On the CI's cell it
    // does not reliably: 0.94 of the region's chi2 rise once (mu_s 0.293 [0.233, 0.378], mu_r 0.064
    // [0.029, 0.080]), 1.60 on 28 November (mu_s 0.258 [0.218, 0.350]) and 1.68 with the search's screening
    // (0.263 [0.218, 0.342]), so there it is printed, not asserted: it turns on the search's path. The fits lean to less
    // sliding and more rolling friction than YADE's, and without the cell's bias the simulator misses these data
    // by more than their noise. Not because it shears three times faster than the
    // data (at the data's I = 1e-3, `triaxdem calibrate` gives mu_s 0.30 [0.23, 0.37], mu_r 0.08 on its range's
    // edge), but because its cell is small: with 600 balls instead of 150, calibrate gives mu_s 0.375 [0.324,
    // 0.471], mu_r 0.034 [0.009, 0.051]. That cell is the long case (ctest -L long), where the region must hold
    // YADE's values: there diagnose gives mu_s 0.411 [0.335, 0.503], mu_r 0.035 [0.017, 0.075] and (0.4, 0.04)
    // at the minimum (rise -0.06), verdict none with wear closest (BIC 5.2 lower, 6 needed), 22 minutes on 2
    // shared cores.
    const Real rise = dg.base.region_rise({0.4, 0.04});
    std::printf("  generating friction (0.4, 0.04): chi2 rise %.2f of the joint 95%% region's (inside at most 1)\n",
                rise);
    if (c.cell_factor > 1 || c.region)
      EXPECT_LE(rise, 1.0) << "the generating friction lies outside the joint 95% region";
  } else {
    for (const ExtensionFit& f : dg.fits)
      if (f.ext.name == c.verdict) {  // the report's claim: both tests passed by the margin
        EXPECT_GE(dg.base_bic - f.bic, kStrongEvidence) << "BIC " << dg.base_bic << " -> " << f.bic;
        EXPECT_GE(dg.base_heldout - f.heldout, kStrongEvidence) << "held-out " << dg.base_heldout << " -> " << f.heldout;
      }
  }
}

INSTANTIATE_TEST_SUITE_P(Yade, CrossCode,
                         ::testing::Values(CrossCase{"linear", "linear_seed1.csv", "linear_base.toml", "none"},
                                           CrossCase{"hertz", "hertz_seed1.csv", "hertz_base.toml", "hertz"}),
                         case_name);
// Outside the suite's budget (label long, tests/CMakeLists.txt): the linear data on a cell of 600 balls; and the data
// of YADE's walled test (walled_seed1.csv: 1000 balls between six walls under TriaxialStressController, stresses at the
// walls) diagnosed with the walled cell of the data's 1000 balls (walled_base.toml, reference_test = "walls"), whose
// joint 95% region must hold the generating friction. It does since the base config raised the overlap guard
// (overlap_limit 0.25): on 30 November mu_s 0.559 [0.370, 0.730], mu_r 0.0055 [0, 0.044], correlation -0.86, (0.4,
// 0.04) at 0.55 of the region's chi2 rise, verdict none (no extension passes against the base: the lowest BIC, wear, is
// 2.2 higher than the base's; the best generic shape, eps_v scaled by 0.81, lowers the chi2 from 13.0 to 9.3 on 60 data
// and not the BIC), 643 s alone on 2 cores, 55 minutes beside a sweep. Before, most runs at 300 kPa stopped at the
// default 10% guard and counted as missing data, and the fits gave (0.355, 0.036) at 1.44 of the rise, (0.73, 0.0003)
// at the data's rate. Forward, at (0.4, 0.04) and the data's void ratio, triaxdem's walled q lies 4-12% above YADE's
// from 3% strain on (tests/data/crosscode/forward_walled.sh), which pulls the fit along the mu_s-mu_r ridge.
INSTANTIATE_TEST_SUITE_P(LongYade, CrossCode,
                         ::testing::Values(CrossCase{"linear_600", "linear_seed1.csv", "linear_base.toml", "none", 4},
                                           CrossCase{"walled", "walled_seed1.csv", "walled_base.toml", "none", 1,
                                                     true}),
                         case_name);

// Outside the suite's budget too: the walled data calibrated against the periodic cell, as a user who does not know
// the data had walls would, and the walled cell run at that optimum (`--predict walls`). The periodic cell measures
// no boundary, so the calibration puts the walls' looser layer and stress measure into friction, and the walled
// test at the calibrated friction reads far above the data: the report states that share. Measured (1000
// balls, box 28 mm for random insertion, 2 cores, 10 minutes) the cell gave mu_s 0.844 [0.625, 0.914], mu_r 0.062,
// chi2 172 on 60 data, and the walled cell there read 255, 511 and 767 kPa at 100, 200 and 300 kPa against the
// data's 136, 298 and 433 (+72 to +88%), the walls' share 40-46% of its q_peak. The bounds below, a share of a
// fifth and an excess of a fifth, are half of what was seen: the members' scatter (7-19 kPa) is a few % of q, so
// anything under a fifth would mean the cell and the walled test measure about the same, which is what this
// test must rule out.
TEST(LongWalledData, APeriodicCalibrationStatesTheWallsShare) {
  const std::string dir = std::string(TRIAXDEM_SOURCE_DIR) + "/tests/data/crosscode/";
  const MeasuredData data = load_measured(dir + "walled_seed1.csv");
  Config periodic = reference_cell(load_config(dir + "walled_base.toml"), "periodic");
  periodic.box.size = {28e-3, 28e-3, 28e-3};  // random insertion of 1000 balls needs room in a periodic box
  StateMatch state;
  const Config cfg = matched_state(periodic, data.tests, state, false, match_plan(periodic, 2));
  PeriodicLab lab(cfg, false, 2);
  const Model base = model_of(cfg);
  const std::vector<FreeParam> free{free_param("mu_s", base), free_param("mu_r", base)};
  const CalibrationResult r = calibrate(lab, base, free, data.tests, measure_misfit(lab, base, data.tests,
                                                                                      NoiseOptions()));
  StateMatch walls_state;
  const Config cell = reference_cell(periodic, kPredictWalls);
  const Config walls = matched_state(cell, data.tests, walls_state, false, match_plan(cell, 2));
  std::vector<Prediction> p = predict_walls(walls, r.model, data.tests, 2, 2);
  ASSERT_EQ(p.size(), r.best.sim.size());
  for (std::size_t k = 0; k < p.size(); ++k) p[k].periodic_q_peak = r.best.sim[k].q_peak;
  std::printf("periodic calibration of walled data: mu_s %.4g [%.4g, %.4g], mu_r %.4g, chi2 %.1f\n%s", r.values[0],
              r.interval[0].first, r.interval[0].second, r.values[1], r.best.chi2,
              prediction_markdown(p, data.q_measure).c_str());
  for (const Prediction& x : p) {
    EXPECT_GT((x.q_peak_mean - x.periodic_q_peak) / x.q_peak_mean, 0.2) << x.measured.sigma3 << " Pa";
    EXPECT_GT(x.error, 0.2) << x.measured.sigma3 << " Pa: the walled test at the periodic optimum";
  }
}

// Issue 62, item 4: the walled cell compares the q the data name. YADE's walled curves hold q over the current face
// area; the same curves over the cross-section at the start of shear (q A / A0 = q (1 - eps_v) / (1 - eps_a), the
// fixed-area q of a lab that does not correct) are another file of the same test. Calibrated against the walled
// cell reading each measure (the same matched state, so the two fits differ only in the q compared), each friction
// must lie in the other's 95% interval: a cell that compared one q with the other would move mu_s by the 16-19% the
// two measures differ at the peak, outside intervals of about +-10%.
TEST(LongWalledData, EachQMeasureCalibratesToTheSameFriction) {
  const std::string dir = std::string(TRIAXDEM_SOURCE_DIR) + "/tests/data/crosscode/";
  const MeasuredData corrected = load_measured(dir + "walled_seed1.csv");
  ASSERT_EQ(corrected.q_measure, QMeasure::kAreaCorrected);
  MeasuredData fixed = corrected;
  fixed.q_measure = QMeasure::kFixedArea;
  for (TriaxialTest& t : fixed.tests) {
    for (std::size_t k = 0; k < t.q.size(); ++k) t.q[k] *= (1 - t.eps_v[k]) / (1 - t.eps_a[k]);
    summarise(t);
  }
  const Config cell = reference_cell(load_config(dir + "walled_base.toml"), kPredictWalls);
  StateMatch state;
  const Config cfg = matched_state(cell, corrected.tests, state, false, match_plan(cell, 2));
  const Model base = model_of(cfg);
  const std::vector<FreeParam> free{free_param("mu_s", base), free_param("mu_r", base)};
  std::vector<CalibrationResult> fits;
  for (const MeasuredData* d : {&corrected, static_cast<const MeasuredData*>(&fixed)}) {
    PeriodicLab lab(cfg, false, 2);
    lab.set_q_measure(d->q_measure);
    fits.push_back(calibrate(lab, base, free, d->tests, measure_misfit(lab, base, d->tests, NoiseOptions())));
    std::printf("%s: mu_s %.4g [%.4g, %.4g], mu_r %.4g [%.4g, %.4g], chi2 %.1f\n", name_of(d->q_measure),
                fits.back().values[0], fits.back().interval[0].first, fits.back().interval[0].second,
                fits.back().values[1], fits.back().interval[1].first, fits.back().interval[1].second,
                fits.back().best.chi2);
  }
  for (int i = 0; i < 2; ++i)
    for (std::size_t p = 0; p < free.size(); ++p) {
      const auto& in = fits[1 - i].interval[p];
      EXPECT_GE(fits[i].values[p], in.first) << free[p].name << " of fit " << i;
      EXPECT_LE(fits[i].values[p], in.second) << free[p].name << " of fit " << i;
    }
}

}  // namespace

namespace {
/// The mean over a lab's specimens of f(specimen).
template <class F>
Real mean_of(const PeriodicLab& lab, int n, F f) {
  Real sum = 0;
  for (int k = 0; k < n; ++k) sum += f(lab.specimen(k));
  return sum / n;
}
}  // namespace

// The layer's law on real packings: walled cells of the cross-code base (monodisperse 2 mm balls, preparation
// friction 0.1) of 500 balls predict, from their interior, the void ratio of cells of 8 times the balls packed
// alike, where their own void ratio misses it by the share of the walls' layer. A cell's void ratio scatters by
// about 0.011 at 120 balls (perf/specimen_scatter.sh), so by about 0.005 at 500: the mean of 4 small and 2 large
// specimens holds the prediction within about 0.004, against a whole cell's miss of 0.10. The prediction takes
// away more than half of the miss, not all (0.7627 predicted, 0.7223 packed, 0.8241 the small cells' own): the
// larger cells' interior also packs denser (solid fraction +0.004 to +0.011, by margin) and their faces' deficit
// falls 2.3-2.9 times where N^-1/3 says 2 (the edges' share, N^-2/3), and the law holds the faces' share alone
// (host/lab/wall_layer.hpp). About 2 minutes on 2 cores (the larger cells' packing).
TEST(LongWalledData, ACellsInteriorPredictsTheVoidRatioOfACellOfEightTimesItsBalls) {
  Config cfg = load_config(std::string(TRIAXDEM_SOURCE_DIR) + "/tests/data/crosscode/walled_base.toml");
  constexpr int kSmall = 500, kFactor = 8;
  const Real shrink = std::cbrt(static_cast<Real>(kSmall) / static_cast<Real>(cfg.particles.count));
  cfg.particles.count = kSmall;
  for (Real& side : cfg.box.size) side *= shrink;
  const PeriodicLab small(cfg, false, 4, 1, 4, 2), large(larger_cell(cfg, kFactor), false, 2, 1, 2, 2);
  const Real data_balls = static_cast<Real>(kSmall * kFactor);
  const Real predicted = mean_of(small, 4, [&](const PackedCell& s) {
    return void_ratio_at_size(s.balls, s.cell, data_balls);
  });
  const Real whole = mean_of(small, 4, [](const PackedCell& s) { return s.void_ratio; });
  const Real actual = mean_of(large, 2, [](const PackedCell& s) { return s.void_ratio; });
  std::printf("void ratio of %d-ball cells %.4f; of %d-ball cells %.4f; predicted from the smaller's interior %.4f\n",
              kSmall, whole, kSmall * kFactor, actual, predicted);
  EXPECT_LT(std::fabs(predicted - actual), std::fabs(whole - actual) / 2);
  EXPECT_LT(actual, predicted) << "the faces' share alone: the larger cells' interior packs denser too";
}
