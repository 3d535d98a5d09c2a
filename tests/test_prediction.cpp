// The loop closed (host/fit/prediction.hpp): the membrane test at calibrated parameters beside the data, on the tiny
// membrane specimen of test_triaxial.cpp (16 mm, 452 beads, seconds a run).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "host/fit/calibrate.hpp"
#include "host/fit/diagnose.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/fit/prediction.hpp"
#include "host/lab/periodic_lab.hpp"
#include "host/triax/triaxial.hpp"
#include "host/fit/two_fidelity.hpp"
#include "test_util.hpp"

using namespace dem;

namespace {

std::string refusal(const Config& c, const std::string& key) {
  try {
    check_prediction_template(c, key);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// The template gets the calibrated contact parameters, on the balls and on the walls where it gives them no
// law of their own, the data's pressure and the member's packing seed; the periodic cell's membrane extension
// is no parameter of the membrane test and is left out.
TEST(Prediction, TheTemplateTakesTheCalibratedContactParameters) {
  Config t = test::tiny_triaxial_config(0.15, 0.015);
  t.path = "tiny.toml";
  t.wall.mu_r = 0.1;  // the walls' own rolling resistance
  Model m{t.ball, 0};
  set_param(m, "mu_s", 0.3);
  set_param(m, "mu_r", 0.04);
  set_param(m, "membrane_kPa", 50e3);
  const Config c = prediction_config(t, m, {"mu_s", "mu_r", "membrane_kPa"}, 200e3, 2);
  EXPECT_EQ(c.ball.mu_s, 0.3);
  EXPECT_EQ(c.ball.mu_r, 0.04);
  EXPECT_EQ(c.wall.mu_s, 0.3);   // followed the balls, as the template's wall did
  EXPECT_EQ(c.wall.mu_r, 0.1);   // its own value kept
  EXPECT_EQ(c.triaxial.sigma3, 200e3);
  EXPECT_EQ(c.run.seed, t.run.seed + 2);
  EXPECT_EQ(c.ball.emod, t.ball.emod);  // not free: the template's
}

// A periodic config is no membrane test, and a specimen under 8 diameters across is refused with the key and
// the smallest size; the tiny specimen (8 across) passes.
TEST(Prediction, ATemplateThatCannotHoldTheSpecimenIsRefused) {
  Config t = test::tiny_triaxial_config(0.15, 0.015);
  t.path = "tiny.toml";
  EXPECT_EQ(refusal(t, "--predict"), "");
  t.specimen.diameter = 12e-3;
  const std::string e = refusal(t, "--predict");
  EXPECT_NE(e.find("tiny.toml: [specimen] diameter_mm: 12 mm is 6.0 particle diameters across; a membrane test "
                   "for --predict needs at least 8 (16 mm)"),
            std::string::npos) << e;
  t.has_specimen = false;
  EXPECT_NE(refusal(t, "[calibrate] predict").find("not a membrane test"), std::string::npos);
}

// Each prediction is the membrane test itself at the calibrated parameters (the same run, bit for bit), its q in
// the data's measure; the error is against the data's peak; a stronger friction predicts a stronger specimen.
TEST(Prediction, EachPressureIsTheMembraneTestAtTheCalibratedParameters) {
  const auto dir = test::scratch_dir("prediction");
  const Config t = test::tiny_triaxial_config(0.15, 0.015);
  Model m{t.ball, 0};
  set_param(m, "mu_s", 0.3);
  std::vector<TriaxialTest> data(2);
  data[0].material = data[1].material = "S-x";
  data[0].sigma3 = 100e3;
  data[1].sigma3 = 200e3;
  data[0].q_peak = 150e3;
  data[1].q_peak = 300e3;
  const std::vector<Prediction> p =
      predict(t, m, {"mu_s"}, data, QMeasure::kAreaCorrected, 1, (dir / "specimens").string(), false);
  ASSERT_EQ(p.size(), 2u);
  for (std::size_t j = 0; j < 2; ++j) {
    ASSERT_EQ(p[j].members.size(), 1u);
    EXPECT_EQ(p[j].q_peak_mean, p[j].members[0].q_peak);
    EXPECT_EQ(p[j].q_peak_sd, 0.0);
    EXPECT_NEAR(p[j].error, (p[j].q_peak_mean - data[j].q_peak) / data[j].q_peak, 1e-15);
  }
  {  // the first pressure run again by hand
    const std::size_t j = 0;
    const Config c = prediction_config(t, m, {"mu_s"}, data[j].sigma3, 0);
    const TriaxialResult r = run_triaxial(c, build_specimen(c, false), nullptr, false);
    EXPECT_EQ(p[j].members[0].q_peak, curves_of(r, &TriaxialRecord::q_area, data[j].sigma3).q_peak);
    EXPECT_NE(p[j].members[0].q_peak, r.q_peak);  // the fixed-area q is another number
  }
  EXPECT_GT(p[1].q_peak_mean, p[0].q_peak_mean);  // the higher pressure
  set_param(m, "mu_s", 0.05);
  const std::vector<Prediction> weak =
      predict(t, m, {"mu_s"}, {data[0]}, QMeasure::kAreaCorrected, 1, (dir / "specimens").string(), false);
  EXPECT_LT(weak[0].q_peak_mean, 0.9 * p[0].q_peak_mean);
  const std::string md = prediction_markdown(p, QMeasure::kAreaCorrected);
  EXPECT_NE(md.find("q as the data report it: area_corrected"), std::string::npos) << md;
  // The files a calibration writes, and the figure tools/plot_prediction.py draws from them.
  io::write_text_atomic((dir / "prediction.csv").string(), prediction_csv(p, QMeasure::kAreaCorrected));
  std::vector<TriaxialTest> curves;
  for (const Prediction& x : p) curves.insert(curves.end(), x.members.begin(), x.members.end());
  write_measured_curves((dir / "prediction_curves.csv").string(), curves, "test", "area_corrected");
  const MeasuredData back = load_measured((dir / "prediction_curves.csv").string());
  EXPECT_EQ(back.q_measure, QMeasure::kAreaCorrected);
  ASSERT_EQ(back.tests.size(), 2u);
  EXPECT_EQ(back.tests[0].replicate, "1");
  const std::string cmd = std::string("/usr/bin/python3 " TRIAXDEM_SOURCE_DIR "/tools/plot_prediction.py ") +
                          dir.string() + " > /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  EXPECT_TRUE(std::filesystem::exists(dir / "prediction.png"));
}

// The membrane tests of a -j 2 calibration ran one at a time on one thread, the other core idle (7 minutes of the 27
// of Table 6's S-1 with two fidelities, twice): with workers, each specimen is built and tested in a child, and the
// tests are those of one at a time, bit for bit (curves, peak, void ratio, balls), labelled by specimen. It runs at
// one thread only (tests/CMakeLists.txt): forking a multithreaded OpenMP process is unsafe, and runs_at_once says 1.
TEST(Prediction, MembraneTestsSideBySideGiveTheTestsOneAtATime) {
  const auto dir = test::scratch_dir("prediction_side_by_side");
  Config t = test::tiny_triaxial_config(0.15, 0.015);
  t.triaxial.axial_strain_end = 0.01;
  const Model m{t.ball, 0};
  std::vector<TriaxialTest> data(2);
  data[0].material = data[1].material = "S-x";
  data[0].sigma3 = 100e3;
  data[1].sigma3 = 200e3;
  data[0].q_peak = data[1].q_peak = 150e3;
  const std::vector<Prediction> one =
      predict(t, m, {"mu_s"}, data, QMeasure::kAreaCorrected, 2, (dir / "apart").string(), false, 1);
  ASSERT_EQ(runs_at_once(2), 2) << "the tests fork only from a one-thread process (ctest runs this test so)";
  const std::vector<Prediction> side =
      predict(t, m, {"mu_s"}, data, QMeasure::kAreaCorrected, 2, (dir / "together").string(), false, 2);
  ASSERT_EQ(side.size(), 2u);
  for (std::size_t j = 0; j < 2; ++j) {
    ASSERT_EQ(side[j].members.size(), 2u);
    for (std::size_t k = 0; k < 2; ++k) {
      const TriaxialTest &a = one[j].members[k], &b = side[j].members[k];
      ASSERT_GT(a.q.size(), 2u);
      EXPECT_EQ(b.q, a.q) << "test " << j << " specimen " << k;
      EXPECT_EQ(b.eps_v, a.eps_v);
      EXPECT_EQ(b.q_peak, a.q_peak);
      EXPECT_EQ(b.void_ratio, a.void_ratio);
      EXPECT_EQ(b.specimen_balls, a.specimen_balls);
      EXPECT_EQ(b.sigma3, a.sigma3);
      EXPECT_EQ(b.replicate, std::to_string(k + 1));
      EXPECT_EQ(b.material, "S-x");
    }
    EXPECT_NE(one[j].members[0].q, one[j].members[1].q) << "two specimens";
    EXPECT_EQ(side[j].q_peak_mean, one[j].q_peak_mean);
  }
}

// A periodic calibration of data from a walled test ends with the walled cell at the calibrated parameters
// (--predict walls): each member is the walled cell's own run there, bit for bit, labelled with the data's material,
// the mean and sample sd are over the members, and the table gives the walls' share against the periodic cell's
// q_peak with its range in words.
TEST(Prediction, TheWalledPredictionIsTheWalledCellsRunsAtTheCalibratedPoint) {
  const Config walls = reference_cell(test::tiny_cell_config(), kPredictWalls);
  ASSERT_EQ(walls.periodic.boundary, CellBoundary::walls);
  Model m{walls.ball, 0};
  set_param(m, "mu_s", 0.4);
  std::vector<TriaxialTest> data(2);
  for (int k = 0; k < 2; ++k) {
    data[k].material = "W";
    data[k].sigma3 = 100e3 * (k + 1);
    data[k].q_peak = 150e3 * (k + 1);
  }
  std::vector<Prediction> p = predict_walls(walls, m, data, 2, 1);
  ASSERT_EQ(p.size(), 2u);
  PeriodicLab lab(walls, false, 2, walls.run.seed, 2, 1);
  for (int k = 0; k < 2; ++k) {
    ASSERT_EQ(p[k].members.size(), 2u);
    const TriaxialTest a = lab.run(m, data[k].sigma3, "W", 0), b = lab.run(m, data[k].sigma3, "W", 1);
    ASSERT_GT(a.q.size(), 5u);
    EXPECT_EQ(p[k].members[0].q, a.q);
    EXPECT_EQ(p[k].members[1].q, b.q);
    EXPECT_NE(a.q, b.q) << "two specimens";
    EXPECT_EQ(p[k].members[1].material, "W");
    EXPECT_EQ(p[k].members[1].replicate, "2");
    EXPECT_DOUBLE_EQ(p[k].q_peak_mean, (a.q_peak + b.q_peak) / 2);
    EXPECT_NEAR(p[k].q_peak_sd, std::fabs(a.q_peak - b.q_peak) / std::sqrt(2.0), 1e-9 * a.q_peak);
    EXPECT_DOUBLE_EQ(p[k].error, (p[k].q_peak_mean - data[k].q_peak) / data[k].q_peak);
  }
  p[0].periodic_q_peak = 0.8 * p[0].q_peak_mean;  // the walls carry a fifth of the first, a third of the second
  p[1].periodic_q_peak = (2.0 / 3) * p[1].q_peak_mean;
  const std::string md = prediction_markdown(p, QMeasure::kFixedArea);
  EXPECT_NE(md.find("| 20% |"), std::string::npos) << md;
  EXPECT_NE(md.find("| 33% |"), std::string::npos) << md;
  EXPECT_NE(md.find("The boundary's share of the predicted q_peak is 20 to 33%"), std::string::npos) << md;
  EXPECT_NE(walled_cell_text(walls).find("between six walls (100 balls"), std::string::npos);
  // Issue 87: one share said as a range of one ("83 to 83%").
  p[1].periodic_q_peak = 0.8 * p[1].q_peak_mean;
  const std::string same = prediction_markdown(p, QMeasure::kFixedArea);
  EXPECT_NE(same.find("The boundary's share of the predicted q_peak is 20%:"), std::string::npos) << same;
}
