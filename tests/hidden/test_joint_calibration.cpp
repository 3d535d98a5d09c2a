/// Tests of two types calibrated together (issue 88): triaxial curves and an oedometer made at one model on specimens
/// the calibration never runs, fitted with the contact stiffness and the friction free.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "host/config/config.hpp"
#include "host/fit/calibrate.hpp"
#include "host/fit/compression_misfit.hpp"
#include "host/fit/diagnose.hpp"
#include "host/fit/misfit.hpp"

using namespace dem;

namespace {

void print(const char* what, const CalibrationResult& r) {
  std::printf("%s: emod %.4g [%.4g, %.4g], mu_s %.4g [%.4g, %.4g], chi2 %.1f on %d data\n", what, r.values[0],
              r.interval[0].first, r.interval[0].second, r.values[1], r.interval[1].first, r.interval[1].second,
              r.best.chi2, r.data);
}

/// The data of the tests below: the generator (the hidden-effect cell at emod 2e8 Pa, mu_s 0.25) on four foreign
/// specimens packed from `first_seed`: three triaxial tests (100-300 kPa, lab-like noise drawn from `noise_seed`) on
/// the first three, an oedometer from 100 to 800 kPa on the fourth.
struct JointData {
  std::vector<TriaxialTest> triaxial;
  std::vector<CompressionTest> oedometer;
};

JointData joint_data(const Config& cfg, unsigned first_seed, unsigned noise_seed) {
  Model truth = model_of(cfg);
  set_param(truth, "emod_Pa", 2e8);
  set_param(truth, "mu_s", 0.25);
  PeriodicLab generator(cfg, false, 4, first_seed, 0, 2);
  JointData d;
  d.triaxial = synthetic_tests(generator, truth, {100e3, 200e3, 300e3}, "joint", noise_seed, 1);
  const CompressionTest like{"joint", CompressionPath::oedometer, 100e3, {200e3, 400e3, 800e3}, {}, {}, {}, {}};
  d.oedometer.push_back(generator.run_compression(truth, like, 3));
  return d;
}

/// The analyser of such data: the base's lab (its own specimens), emod and mu_s free, the misfit of the triaxial tests
/// and the oedometer's, each scatter measured at the base.
struct JointAnalysis {
  JointAnalysis(const Config& cfg, const JointData& d)
      : lab(cfg, false, 2),
        base(model_of(cfg)),
        free{free_param("emod_Pa", base), free_param("mu_s", base)},
        misfit(measure_misfit(lab, base, d.triaxial, NoiseOptions(), false)),
        compression(d.oedometer, lab.run_compressions(base, d.oedometer, true), lab.members()) {}
  PeriodicLab lab;
  Model base;
  std::vector<FreeParam> free;
  Misfit misfit;
  CompressionMisfit compression;
};

}  // namespace

// The generator: tests/data/hidden_effects.toml's cell (120 balls) at emod 2e8 Pa and mu_s 0.25, twice the base's
// stiffness and 1.7 times its friction, so that the search must move; three triaxial tests (100-300 kPa, lab-like
// noise) of which the data keep the peak deviator alone, as Table 6 gives, and an oedometer from 100 to 800 kPa, each
// on its own specimen packed with seeds the calibration's ensemble never uses (kForeignSeedOffset). Calibrated from the
// base (1e8, 0.15) with emod and mu_s free, each generating value must lie in its 95% interval, and the oedometer must
// pin emod, which peaks hardly see: its interval at most half as wide (in log emod) as the peaks' alone. (Whole curves
// pin emod by their initial stiffness already: with them both fits gave emod [1.87e8, 2.23e8].) Measured: emod 2.04e8
// [1.62e8, 2.41e8], mu_s 0.245 [0.209, 0.287] with the oedometer (chi2 3.6 on 9 data); the peaks alone left emod its
// whole range [3.3e7, 3e8]. About 3 minutes on 2 cores. The data's specimens are prepared at the base's emod, as the
// cells are. Prepared at the truth's, the same seeds pack other specimens, and this draw of three 120-ball peaks then
// put mu_s at 0.357 [0.287, 0.403] (3 December): the preparation's stiffness does not move the peak
// (data/sweeps/preparation: 32 specimens, within 0.015 in mu_s), the draw does, beyond what the intervals count for
// peaks of specimens this small; this test asks for the oedometer's pin and an answer at one fixed draw.
TEST(JointCalibration, AnOedometerWithTriaxialPeaksRecoversTheStiffnessAndTheFriction) {
  const Config cfg = load_config(std::string(TRIAXDEM_SOURCE_DIR) + "/tests/data/hidden_effects.toml");
  JointData data = joint_data(cfg, cfg.run.seed + kForeignSeedOffset, 1);
  ASSERT_TRUE(std::isfinite(data.oedometer.front().strain.back()));
  for (TriaxialTest& t : data.triaxial) {  // the peak deviator alone
    TriaxialTest p;
    p.material = t.material, p.sigma3 = t.sigma3, p.q_peak = t.q_peak;
    p.eps_a_peak = p.q_end = p.max_dilatancy = p.e_ini = p.q_1pct = p.q_3pct = std::nan("");
    t = p;
  }
  JointAnalysis a(cfg, data);
  const std::vector<TriaxialTest>& peaks = data.triaxial;
  const std::vector<FreeParam>& free = a.free;
  const Misfit& misfit = a.misfit;
  const CompressionMisfit& compression = a.compression;
  const CalibrationResult joint = calibrate(a.lab, a.base, free, peaks, misfit, 4, {}, 2, compression.joint(a.lab));
  const CalibrationResult alone = calibrate(a.lab, a.base, free, peaks, misfit);
  print("peaks and oedometer", joint);
  print("peaks alone", alone);
  EXPECT_EQ(joint.data, misfit.data() + compression.data());
  const Real truth_values[2] = {2e8, 0.25};
  for (int k = 0; k < 2; ++k) {
    EXPECT_GE(truth_values[k], joint.interval[k].first) << free[k].name;
    EXPECT_LE(truth_values[k], joint.interval[k].second) << free[k].name;
  }
  const auto log_width = [](const CalibrationResult& r) { return std::log(r.interval[0].second / r.interval[0].first); };
  EXPECT_LT(log_width(joint), 0.5 * log_width(alone));
}

// diagnose --compression: an oedometer joins the triaxial curves in the base fit and in every extension's, and counts
// in the data the verdict weighs. Data made as above (emod 2e8, mu_s 0.25, no extension): three curves (100-300 kPa)
// and the oedometer, each on a foreign specimen; diagnosed with emod and mu_s free. Every fit's residuals must carry
// the oedometer's after the curves' (an extension fit that dropped them would compare its chi2 with a base chi2 that
// has them), and the oedometer must pin emod in the base fit as in the calibration above. The verdict is printed, not
// asked: 120-ball data specimens scatter more than the lab's the diagnosis assumes (test_hidden_effects.cpp makes its
// data in cells four times larger for that). About 4 minutes on 2 cores.
TEST(JointCalibration, ADiagnosisFitsTheOedometerInEveryFit) {
  const Config cfg = load_config(std::string(TRIAXDEM_SOURCE_DIR) + "/tests/data/hidden_effects.toml");
  const JointData data = joint_data(cfg, cfg.run.seed + kForeignSeedOffset + 10, 2);
  ASSERT_TRUE(std::isfinite(data.oedometer.front().strain.back()));
  JointAnalysis a(cfg, data);
  const Misfit& misfit = a.misfit;
  const CompressionMisfit& compression = a.compression;
  const Diagnosis dg = diagnose(a.lab, a.base, a.free, data.triaxial, misfit, false, compression.joint(a.lab));
  print("diagnosis's base fit", dg.base);
  std::printf("verdict %s: %s\n", dg.verdict.c_str(), dg.explanation.c_str());
  const std::size_t n = static_cast<std::size_t>(misfit.data() + compression.data());
  EXPECT_EQ(dg.base.data, static_cast<int>(n));
  EXPECT_EQ(dg.base.best.r.size(), n);
  ASSERT_FALSE(dg.fits.empty());
  for (const ExtensionFit& f : dg.fits) EXPECT_EQ(f.best.r.size(), n) << f.ext.name;
  EXPECT_GE(2e8, dg.base.interval[0].first);
  EXPECT_LE(2e8, dg.base.interval[0].second);
}
