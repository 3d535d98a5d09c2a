// Measured triaxial data (host/measured.hpp): the shipped Table 6, curves, and refusals with line and column.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "host/diagnose.hpp"
#include "host/measured.hpp"
#include "test_util.hpp"

using namespace dem;

namespace {

std::string write(const std::string& name, const std::string& text) {
  static const auto dir = dem::test::scratch_dir("measured");
  std::ofstream(dir / name) << text;
  return (dir / name).string();
}

std::string error_of(const std::string& text) {
  try {
    load_measured(write("bad.csv", text));
  } catch (const DataError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Measured, ShippedTable6Loads) {
  const MeasuredData d = load_measured(std::string(TRIAXDEM_SOURCE_DIR) + "/data/tang2025_table6_peak.csv");
  EXPECT_FALSE(d.curves);
  ASSERT_EQ(d.tests.size(), 9u);
  EXPECT_EQ(d.tests[3].material, "S-2");
  EXPECT_DOUBLE_EQ(d.tests[3].sigma3, 100e3);
  EXPECT_DOUBLE_EQ(d.tests[8].q_peak, 667.26e3);  // kPa in the file, Pa inside
  EXPECT_TRUE(std::isnan(d.tests[0].eps_a_peak));  // not given
  check_pressures(d, {100e3, 200e3, 300e3});
  try {
    check_pressures(d, {100e3, 200e3});
    FAIL() << "300 kPa has no config";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("at sigma3 = 300 kPa"), std::string::npos) << e.what();
  }
}

// A plateau whose last record is a spike: towards the end the moving mean's window shrinks to that record,
// so the peak is sought only where the window is whole (the full-scale S-1 at 100 kPa reported its last
// record, 144.1 kPa, as the peak of a plateau near 138 kPa before this).
TEST(Measured, AnEndRecordIsNotTakenForThePeak) {
  std::ostringstream f;
  f << "material,sigma3_kPa,eps_a_pct,q_kPa\n";
  for (int i = 0; i <= 50; ++i) f << "A,100," << 0.1 * i << "," << (i == 50 ? 120.0 : 100.0 + (i % 2 ? 3 : -3)) << "\n";
  const MeasuredTest t = load_measured(write("spike.csv", f.str())).tests[0];
  EXPECT_LT(t.q_peak, 102e3);  // 100 kPa and the mean of the +-3 kPa scatter over 5 or 6 rows
  EXPECT_GT(t.q_peak, 99e3);
  EXPECT_LE(t.eps_a_peak, 0.0475 + 1e-12);
}

TEST(Measured, CurvesInOtherUnitsAreSummarised) {
  const MeasuredData d = load_measured(write("curve.csv",
                                             "# a test\nmaterial,sigma3_MPa,eps_a_frac,q_kPa,eps_v_pct\n"
                                             "A,0.1,0.00,0,0\nA,0.1,0.01,100,0.2\nA,0.1,0.02,150,0.1\n"
                                             "A,0.1,0.03,140,-0.3\n"));
  ASSERT_TRUE(d.curves);
  ASSERT_EQ(d.tests.size(), 1u);
  const MeasuredTest& t = d.tests[0];
  EXPECT_DOUBLE_EQ(t.sigma3, 100e3);
  EXPECT_DOUBLE_EQ(t.q_peak, 150e3);
  EXPECT_DOUBLE_EQ(t.eps_a_peak, 0.02);
  // Rows 1% apart: the +-0.25% smoothing window holds one row, the last 1% of strain two (2% and 3%).
  EXPECT_DOUBLE_EQ(t.q_end, 145e3);
  EXPECT_NEAR(t.max_dilatancy, 0.4, 1e-12);  // -(-0.003 - 0.001) / 0.01
  // Initial stiffness over the first 0.2% of strain: no row but the first lies within it.
  EXPECT_TRUE(std::isnan(t.e_ini));
  // q at 1% and 3% strain: on a row each (one row per smoothing window: the rows themselves).
  EXPECT_DOUBLE_EQ(t.q_1pct, 100e3);
  EXPECT_DOUBLE_EQ(t.q_3pct, 140e3);
}

// Dense rows with alternating scatter: the moving mean over +-0.25% strain removes it, so q_peak is the
// underlying curve's and not the highest noisy row.
TEST(Measured, NoisyCurvesAreSmoothedBeforeTheyAreSummarised) {
  std::ostringstream f;
  f.precision(15);  // the expected values below are computed from unrounded rows
  f << "material,sigma3_kPa,eps_a_pct,q_kPa,eps_v_pct\n";
  for (int i = 0; i <= 1000; ++i) {
    const double e = 0.01 * i;  // % strain, 0.01% apart: 51 rows per window
    const double q = 100 * (1 - std::exp(-e)) + (i % 2 ? 5.0 : -5.0);
    f << "A,100," << e << "," << q << "," << -0.2 * e << "\n";
  }
  const MeasuredTest t = load_measured(write("noisy.csv", f.str())).tests[0];
  // The clean curve rises to the end; the peak is sought where the window is whole, up to 9.75%, where it is
  // 100 (1 - e^-9.75) = 99.994 kPa; the window's mean carries at most one unpaired row: 5/51 ~ 0.1 kPa; the
  // mean of the scatter over the last 1% likewise.
  EXPECT_NEAR(t.q_peak, 99.994e3, 0.15e3);
  // Where in the flat tail: the clean curve gains 100 e^-9.75 * 0.01% = 6e-7 kPa per row, far below the 0.1 kPa
  // of scatter, so anywhere near the end of the searched range, never in the shrunken end window.
  EXPECT_LE(t.eps_a_peak, 0.0975 + 1e-12);
  EXPECT_GT(t.eps_a_peak, 0.09);
  EXPECT_NEAR(t.q_end, 1e5 * (1 - std::exp(-9.5)), 0.2e3);  // mean of a nearly flat tail
  EXPECT_NEAR(t.max_dilatancy, 0.2, 1e-9);                  // eps_v = -0.2 eps_a exactly
  // q at 1% and 3%: the smoothed curve there (51 rows, one unpaired: 0.1 kPa of scatter; the curvature
  // over the +-0.25% window moves the mean by 100 e^-e 0.25^2/6 < 0.4 kPa).
  EXPECT_NEAR(t.q_1pct, 1e5 * (1 - std::exp(-1.0)), 0.5e3);
  EXPECT_NEAR(t.q_3pct, 1e5 * (1 - std::exp(-3.0)), 0.2e3);
  // Initial stiffness: the least-squares slope through the first row over the first 0.2% (rows 1-20), worked
  // out here from the rows as written (strain as a fraction, stress in Pa); rounding only: 1e-9.
  double sxy = 0, sxx = 0;
  auto q_row = [](int i) { return 1e3 * (100 * (1 - std::exp(-0.01 * i)) + (i % 2 ? 5.0 : -5.0)); };
  for (int i = 1; i <= 20; ++i) {
    sxy += 1e-4 * i * (q_row(i) - q_row(0));
    sxx += 1e-8 * i * i;
  }
  EXPECT_NEAR(t.e_ini, sxy / sxx, 1e-9 * sxy / sxx);
  // ... which is the clean initial slope 1e7 Pa lowered ~7% by the curvature and raised ~37% by the -5 kPa
  // scatter of the first row (a 0.2% window is short: the first row's error weighs on the slope).
  EXPECT_NEAR(t.e_ini, 1.3e7, 0.05e7);
}

TEST(Measured, BadFilesAreRefusedWithLineAndColumn) {
  std::string e = error_of("material,sigma3_kPa\nS-1,100\n");
  EXPECT_NE(e.find("bad.csv:1: missing column 'q_peak'"), std::string::npos) << e;
  e = error_of("material,sigma3_kPa,q_peak_kPa\nS-1,100,1x2\n");
  EXPECT_NE(e.find("bad.csv:2:q_peak_kPa: '1x2' is not a number"), std::string::npos) << e;
  e = error_of("material,sigma3_psi,q_peak_kPa\nS-1,100,12\n");
  EXPECT_NE(e.find("bad.csv:1:sigma3_psi: unit 'psi' does not parse"), std::string::npos) << e;
  e = error_of("material,sigma3_kPa,eps_a_pct,q_kPa\nS-1,100,0,0\nS-1,100,1,50\nS-1,100,0.5,60\n");
  EXPECT_NE(e.find("bad.csv:4:eps_a_pct: axial strain must increase"), std::string::npos) << e;
  e = error_of("material,sigma3_kPa,q_peak_kPa\nS-1,100,12\nS-1,100,13\n");
  EXPECT_NE(e.find("bad.csv:3: material S-1 at 100"), std::string::npos) << e;
  e = error_of("material,sigma3_kPa,q_peak_kPa\nS-1,100\n");
  EXPECT_NE(e.find("bad.csv:2: has 2 cells, the header 3"), std::string::npos) << e;
  e = error_of("material,sigma3_kPa,q_peak_kPa,colour\nS-1,100,1,red\n");
  EXPECT_NE(e.find("bad.csv:1:colour: unknown column"), std::string::npos) << e;
  EXPECT_NE(error_of("# only a comment\n").find("no header line"), std::string::npos);
}

// Reference values (the paper's Table 5 beside a calibration): the shipped file loads; a parameter the
// checker does not know, a cell that is not a number and a missing material column are refused with line and
// column.
TEST(Measured, ReferenceValuesLoadAndBadOnesAreRefused) {
  auto known = [](const std::string& n) {
    if (n != "mu_s" && n != "mu_r") throw std::invalid_argument("unknown free parameter '" + n + "'");
  };
  const ReferenceValues t5 = load_reference(std::string(TRIAXDEM_SOURCE_DIR) + "/data/tang2025_table5_friction.csv", known);
  EXPECT_EQ(t5.parameters, (std::vector<std::string>{"mu_s", "mu_r"}));
  EXPECT_DOUBLE_EQ(t5.values.at("S-2").at("mu_s"), 0.3);
  EXPECT_DOUBLE_EQ(t5.values.at("S-3").at("mu_r"), 0.025);
  EXPECT_NE(t5.comment.find("Table 5"), std::string::npos);
  auto error = [&](const std::string& text) {
    try {
      load_reference(write("ref.csv", text), known);
    } catch (const DataError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error("material,mu_s,colour\nS-1,0.1,2\n").find("ref.csv:1:colour: unknown free parameter"),
            std::string::npos);
  EXPECT_NE(error("material,mu_s\nS-1,abc\n").find("ref.csv:2:mu_s: 'abc' is not a number"), std::string::npos);
  EXPECT_NE(error("sample,mu_s\nS-1,0.1\n").find("ref.csv:1:sample: the first column must be 'material'"),
            std::string::npos);
}

// The HDF5 form holds the same data as the CSV: curves written both ways read back to the same tests (the CSV
// keeps 6 digits, hence the tolerance of 1e-5 relative); an HDF5 error names the group, the row and the column.
TEST(Measured, Hdf5FormReadsLikeTheCsv) {
  MeasuredTest a;
  a.material = "S-1";
  a.sigma3 = 100e3;
  for (int i = 0; i <= 400; ++i) {
    a.eps_a.push_back(2.5e-4 * i);
    a.q.push_back(150e3 * (1 - std::exp(-40.0 * a.eps_a.back())));
    a.eps_v.push_back(0.3 * a.eps_a.back() * (a.eps_a.back() - 0.02));
  }
  MeasuredTest b = a;
  b.material = "S-2";
  b.sigma3 = 200e3;
  const std::string csv = write("curves.csv", ""), h5 = write("curves.h5", "");
  write_measured_curves(csv, {a, b}, "test");
  write_measured_curves(h5, {a, b}, "test");
  const MeasuredData dc = load_measured(csv), dh = load_measured(h5);
  ASSERT_TRUE(dh.curves);
  ASSERT_EQ(dh.tests.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(dh.tests[k].material, dc.tests[k].material);
    EXPECT_DOUBLE_EQ(dh.tests[k].sigma3, dc.tests[k].sigma3);
    ASSERT_EQ(dh.tests[k].q.size(), 401u);
    EXPECT_DOUBLE_EQ(dh.tests[k].q[200], (k ? b : a).q[200]);  // HDF5 keeps every bit
    EXPECT_NEAR(dh.tests[k].q_peak, dc.tests[k].q_peak, 1e-5 * dc.tests[k].q_peak);
    EXPECT_NEAR(dh.tests[k].max_dilatancy, dc.tests[k].max_dilatancy, 1e-4);
  }
  b.eps_a[7] = b.eps_a[6];  // strain that does not increase
  write_measured_curves(h5, {a, b}, "test");
  try {
    load_measured(h5);
    ADD_FAILURE() << "accepted a strain that does not increase";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("curves.h5:/S-2/table row 8:eps_a_pct: axial strain must increase"),
              std::string::npos) << e.what();
  }
}
