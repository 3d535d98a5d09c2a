/// Hidden-effect tests: the generator runs the simulator with one model extension switched on (or none) on a
/// specimen per pressure that the diagnosis never runs (packing seeds 100000 above the config's, cells of four
/// times the balls; the file gives their void ratio and particle count, as a user would), adds lab-like
/// noise (host/fit/diagnose.hpp, synthetic_tests) and writes only a measured-data file. The diagnosis reads that file,
/// calibrates the base model on its own ensemble and must name the hidden effect, or none for the null case and
/// for an effect the data cannot show;
/// where an effect was hidden, the extended model must lower the held-out misfit by the strong-evidence margin
/// (kStrongEvidence). A case per extension (hertz among the long cases) and a null case, on the cheap simulator of
/// tests/data/hidden_effects.toml (120 balls, an ensemble of two, the scatter measured on eight; about 500 runs a
/// case, two at a time). The strengths are fixed in the upper half of each extension's physical range, where a
/// lab would notice the effect; perf/hidden_sweep draws them over the whole range and prints the identification
/// rates.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "host/fit/calibrate.hpp"
#include "host/config/config.hpp"
#include "host/fit/diagnose.hpp"
#include "host/data/measured.hpp"
#include "tests/test_util.hpp"

using namespace dem;

namespace {

struct HiddenCase {
  std::string extension;  ///< "none" for the null case
  Real strength;          ///< SI (Pa for the membrane)
  unsigned seed;          ///< noise seed
  unsigned ensemble = 1;  ///< the diagnosis's first packing seed ([run] seed)
  bool auto_ensemble = false;  ///< the diagnosis chooses its ensemble and cell (the default of a user's config)
  Real noise = 1;              ///< the data's lab-like noise times this (0: as precise as a simulation)
  std::string verdict = extension;  ///< the verdict the data allow: "none" where they cannot show the effect
  std::vector<Real> pressures{100e3, 200e3, 300e3};  ///< Pa, a test each
};

void PrintTo(const HiddenCase& c, std::ostream* os) {
  *os << c.extension << " " << c.strength << " ensemble seed " << c.ensemble;
}

class HiddenEffect : public ::testing::TestWithParam<HiddenCase> {};

TEST_P(HiddenEffect, DiagnosisNamesIt) {
  const HiddenCase c = GetParam();
  const Config cfg = load_config(std::string(TRIAXDEM_SOURCE_DIR) + "/tests/data/hidden_effects.toml");
  const std::string file = (test::scratch_dir("hidden_" + c.extension) / "curves.csv").string();
  {  // The generator: its model and lab go out of scope; only the file remains.
    Model truth = model_of(cfg);
    if (c.extension != "none") set_param(truth, extension(c.extension).param, c.strength);
    // A specimen the diagnosis never sees: its ensemble packs with seeds [run] seed, seed + 1, ...
    const unsigned first_seed = cfg.run.seed + kForeignSeedOffset + 3 * c.seed;
    PeriodicLab generator(larger_cell(cfg, kGeneratorCellFactor), false, 3, first_seed, 0, 2);
    write_measured_curves(file, synthetic_tests(generator, truth, c.pressures, "hidden", c.seed, c.noise),
                          "hidden-effect test");
  }
  const MeasuredData data = load_measured(file);
  Config analyser = cfg;
  analyser.run.seed = c.ensemble;
  if (c.auto_ensemble) analyser.calibrate.ensemble = kAutoEnsemble;
  StateMatch state;  // the data's void ratio sets the preparation, as triaxdem diagnose does
  PeriodicLab lab(matched_state(analyser, data.tests, state, false, match_plan(analyser, 2)), false, 2);
  const Model base = model_of(cfg);
  const Diagnosis dg = diagnose(lab, base, {free_param("mu_s", base), free_param("mu_r", base)}, data.tests,
                                measure_misfit(lab, base, data.tests, NoiseOptions()), false);
  std::printf("hidden %s (ensemble seed %u): verdict %s. %s\n", c.extension.c_str(), c.ensemble, dg.verdict.c_str(),
              dg.explanation.c_str());
  for (const ExtensionFit& f : dg.fits) std::printf("  %s: %s\n", f.ext.name.c_str(), f.reason.c_str());
  EXPECT_EQ(dg.verdict, c.verdict) << dg.explanation;
  // What the report claims, asserted: the named extension lowers both BIC and the held-out chi2 by the strong-
  // evidence margin; with none named, no extension does both.
  for (const ExtensionFit& f : dg.fits) {
    const Real bic_gain = dg.base_bic - f.bic, heldout_gain = dg.base_heldout - f.heldout;
    if (f.ext.name == c.verdict) {
      EXPECT_GE(bic_gain, kStrongEvidence) << f.ext.name << ": BIC " << dg.base_bic << " -> " << f.bic;
      EXPECT_GE(heldout_gain, kStrongEvidence) << f.ext.name << ": held-out chi2 " << dg.base_heldout << " -> "
                                               << f.heldout;
    } else if (c.verdict == "none") {
      EXPECT_FALSE(bic_gain >= kStrongEvidence && heldout_gain >= kStrongEvidence)
          << f.ext.name << " passes both tests on null data: BIC gain " << bic_gain
          << ", held-out gain " << heldout_gain;
    }
  }
}

// Wear (0.6, the top of its range) and the membrane (300 kPa) are not run, even as long cases: on specimens the diagnosis never
// ran, with the noise measured rather than assumed, this simulator (120 balls, an ensemble of two, 8% strain) does
// not tell them from specimen scatter. Measured: wear 0.6 gave BIC gains of -3.1 and -1.9 with two
// ensembles (verdict none); the membrane gave 2.2 and the roughness fit 6.5 (verdict roughness, a wrong name).
// They passed before only because the data came from the diagnosis's own specimen. perf/hidden_sweep measures
// their identification rate; a CI case for them needs a larger ensemble or cell than the CI budget allows.
// Long cases (about 2.5 minutes each on 2 cores; ctest -L long). The suite asks the same of data the simulator did
// not make (test_crosscode.cpp): it must name hertz in YADE's Hertz-Mindlin data and nothing in YADE's linear data,
// whose preparation, rate, cell and rolling law differ from the simulator's (a harder null than the simulator's
// own). Roughness hidden in this simulator's own data was the suite's third diagnosis until the suite passed 25
// minutes on 2 cores; it is the cheapest of these to run by hand. Adhesion (100 kPa, the upper half of its range) is
// back on the diagnosis's menu with q offset (an apparent cohesion, issue 63) as the generic rival it must beat: where
// its data show it, it must still be named.
INSTANTIATE_TEST_SUITE_P(LongOneCasePerExtension, HiddenEffect,
                         ::testing::Values(HiddenCase{"roughness", 1e-2, 1}, HiddenCase{"hertz", 3e-3, 1},
                                           HiddenCase{"adhesion", 1e5, 1}, HiddenCase{"none", 0, 1}),
                         [](const ::testing::TestParamInfo<HiddenCase>& i) { return i.param.extension; });

// Twisting resistance at the top of its range (a spin moment capped at 0.2 Rbar Fn: q_peak 32% above the base law's
// in the reference cell, tests/reference/periodic_extensions.csv) cannot be shown by triaxial curves: a slightly
// larger mu_r gives the same curves, so the base calibration fits its data within noise (chi2 16.8 on 60 data with
// lab-like noise, 10.2 with none), and the fit with twist freed ends at the base point. The data allow no name, and
// the diagnosis must give none: neither twist nor a wrong extension. Both noise levels; long cases (about 5 minutes
// each on 2 cores).
INSTANTIATE_TEST_SUITE_P(LongNotIdentifiable, HiddenEffect,
                         ::testing::Values(HiddenCase{"twist", 0.2, 1, 1, false, 1, "none"},
                                           HiddenCase{"twist", 0.2, 1, 1, false, 0, "none"}),
                         [](const ::testing::TestParamInfo<HiddenCase>& i) {
                           return i.param.extension + (i.param.noise == 0 ? "_precise" : "_lab");
                         });

// The verdict must not hinge on the ensemble: the same data, diagnosed by an ensemble of other specimens
// (packing seeds 11, 12, ... instead of 1, 2, ...), give the same verdict. A long case (ctest -L long, about 2
// minutes), beyond the CI's budget.
INSTANTIATE_TEST_SUITE_P(LongAnotherEnsemble, HiddenEffect, ::testing::Values(HiddenCase{"hertz", 3e-3, 1, 11}),
                         [](const ::testing::TestParamInfo<HiddenCase>& i) { return i.param.extension; });

// Data of one test (issue 89): a lab's one curve at one pressure. The held-out check then predicts the curve's later
// half from its earlier and back (heldout_parts), so a verdict can be reached; Hertz hidden at the strength where
// the three pressures' case names it must be named from the 200 kPa test alone, and data of one test without an
// effect get none: the halves must not make false alarms easier. Long cases (ctest -L long, about a minute each).
INSTANTIATE_TEST_SUITE_P(LongOneTest, HiddenEffect,
                         ::testing::Values(HiddenCase{"hertz", 3e-3, 1, 1, false, 1, "hertz", {200e3}},
                                           HiddenCase{"none", 0, 1, 1, false, 1, "none", {200e3}}),
                         [](const ::testing::TestParamInfo<HiddenCase>& i) { return i.param.extension; });

// A precise simulator must not find an effect in precise data that have none. With the ensemble and cell it chooses
// itself, the diagnosis measures its mean to within half of a 480-ball data specimen's scatter, and then sees
// how a cell of 120 balls differs from one of 480 on average. Before that difference was counted (host/fit/cell_bias.hpp)
// these data were named wear (BIC 11.2 lower, held-out chi2 98.0 -> 78.9; docs/history/calibration.md). A long
// case: about 8 minutes on 2 cores (ctest -L long).
INSTANTIATE_TEST_SUITE_P(LongAutoEnsemble, HiddenEffect, ::testing::Values(HiddenCase{"none", 0, 6, 1, true, 0}),
                         [](const ::testing::TestParamInfo<HiddenCase>& i) { return i.param.extension; });

}  // namespace
