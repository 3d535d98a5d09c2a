// Measured triaxial data (host/data/measured.hpp): the shipped Table 6, curves, and refusals with line and column.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "host/fit/diagnose.hpp"
#include "host/data/compression_data.hpp"
#include "host/data/measured.hpp"
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
  const TriaxialTest t = load_measured(write("spike.csv", f.str())).tests[0];
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
  const TriaxialTest& t = d.tests[0];
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
  const TriaxialTest t = load_measured(write("noisy.csv", f.str())).tests[0];
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
  TriaxialTest a;
  a.material = "S-1";
  a.sigma3 = 100e3;
  for (int i = 0; i <= 400; ++i) {
    a.eps_a.push_back(2.5e-4 * i);
    a.q.push_back(150e3 * (1 - std::exp(-40.0 * a.eps_a.back())));
    a.eps_v.push_back(0.3 * a.eps_a.back() * (a.eps_a.back() - 0.02));
  }
  TriaxialTest b = a;
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

// h5py writes a Python str attribute as a variable-length string, which the reader refused ("not a fixed-length
// string") without saying how to write it (issue 65): it is read like a fixed-length one. The file is written as
// h5py writes it, with the C API: a group per material, its `table` of numbers, `columns` a variable-length string.
TEST(Measured, Hdf5FromH5pyWithVariableLengthStringsReads) {
  const std::string path = write("h5py.h5", "");
  {
    const hid_t f = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    const hid_t g = H5Gcreate2(f, "/S-1", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    const hsize_t dims[2] = {2, 2};
    const double rows[4] = {100, 142.4, 200, 255.9};
    const hid_t space = H5Screate_simple(2, dims, nullptr);
    const hid_t d = H5Dcreate2(g, "table", H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, rows);
    const hid_t str = H5Tcopy(H5T_C_S1);
    H5Tset_size(str, H5T_VARIABLE);
    H5Tset_cset(str, H5T_CSET_UTF8);
    const hid_t scalar = H5Screate(H5S_SCALAR);
    const hid_t a = H5Acreate2(d, "columns", str, scalar, H5P_DEFAULT, H5P_DEFAULT);
    const char* columns = "sigma3_kPa,q_peak_kPa";
    H5Awrite(a, str, &columns);
    H5Aclose(a);
    H5Sclose(scalar);
    H5Tclose(str);
    H5Dclose(d);
    H5Sclose(space);
    H5Gclose(g);
    H5Fclose(f);
  }
  const MeasuredData m = load_measured(path);
  ASSERT_EQ(m.tests.size(), 2u);
  EXPECT_DOUBLE_EQ(m.tests[1].q_peak, 255.9e3);
}

// Standard deviations in their own units, each turned into SI: per row in a curve file, per quantity in a
// summary file.
TEST(Measured, StandardDeviationColumnsAreReadInSI) {
  const MeasuredData c = load_measured(write("curve_sd.csv",
                                             "material,sigma3_kPa,eps_a_pct,q_kPa,eps_v_pct,q_sd_MPa,eps_v_sd_frac\n"
                                             "A,100,0,0,0,0.002,0.0001\nA,100,1,100,0.2,0.003,0.0002\n"
                                             "A,100,2,150,0.1,0.004,0.0003\n"));
  ASSERT_EQ(c.tests.size(), 1u);
  EXPECT_EQ(c.tests[0].q_sd, (std::vector<Real>{2e3, 3e3, 4e3}));
  EXPECT_EQ(c.tests[0].eps_v_sd, (std::vector<Real>{1e-4, 2e-4, 3e-4}));
  EXPECT_TRUE(c.tests[0].summary_sd.empty());
  const MeasuredData s = load_measured(write("summary_sd.csv",
                                             "material,sigma3_kPa,q_peak_kPa,q_peak_sd_MPa,eps_a_peak_pct,eps_a_peak_sd_pct,"
                                             "max_dilatancy,max_dilatancy_sd,e_ini_MPa,e_ini_sd_kPa\n"
                                             "A,100,300,0.01,4,0.5,0.3,0.05,50,2000\n"));
  const TriaxialTest& t = s.tests[0];
  EXPECT_DOUBLE_EQ(t.summary_sd.at("q_peak"), 1e4);
  EXPECT_DOUBLE_EQ(t.summary_sd.at("eps_a_peak"), 0.005);
  EXPECT_DOUBLE_EQ(t.summary_sd.at("max_dilatancy"), 0.05);
  EXPECT_DOUBLE_EQ(t.summary_sd.at("e_ini"), 2e6);
  EXPECT_EQ(t.summary_sd.size(), 4u);
  EXPECT_TRUE(t.q_sd.empty());
}

TEST(Measured, BadStandardDeviationsAreRefusedWithLineAndColumn) {
  const std::string curve = "material,sigma3_kPa,eps_a_pct,q_kPa,q_sd_kPa\nA,100,0,0,1\n";
  std::string e = error_of(curve + "A,100,1,50,0\n");
  EXPECT_NE(e.find("bad.csv:3:q_sd_kPa: standard deviation must be > 0"), std::string::npos) << e;
  e = error_of(curve + "A,100,1,50,-2\n");
  EXPECT_NE(e.find("bad.csv:3:q_sd_kPa: standard deviation must be > 0"), std::string::npos) << e;
  e = error_of(curve + "A,100,1,50,inf\n");
  EXPECT_NE(e.find("bad.csv:3:q_sd_kPa: standard deviation must be > 0"), std::string::npos) << e;
  e = error_of(curve + "A,100,1,50,\n");  // given on the first row of the test, not on the second
  EXPECT_NE(e.find("bad.csv:3:q_sd_kPa: missing for part of a test: give it on every row or on none"), std::string::npos)
      << e;
  e = error_of(curve + "A,100,1,50,x\n");
  EXPECT_NE(e.find("bad.csv:3:q_sd_kPa: 'x' is not a number"), std::string::npos) << e;
  e = error_of("material,sigma3_kPa,eps_a_pct,q_kPa,q_peak_sd_kPa\nA,100,0,0,1\n");
  EXPECT_NE(e.find("bad.csv:1:q_peak_sd_kPa: a curve file has no standard deviation of q_peak (allowed: "
                   "q_sd_<unit>, eps_v_sd_<unit>, void_ratio_sd, porosity_sd)"),
            std::string::npos) << e;
  e = error_of("material,sigma3_kPa,eps_a_pct,q_kPa,eps_v_sd_pct\nA,100,0,0,1\n");
  EXPECT_NE(e.find("bad.csv:1:eps_v_sd_pct: a standard deviation of eps_v, which the file does not give"),
            std::string::npos) << e;
  e = error_of("material,sigma3_kPa,q_peak_kPa,sigma3_sd_kPa\nA,100,300,1\n");
  EXPECT_NE(e.find("bad.csv:1:sigma3_sd_kPa: a summary file has no standard deviation of sigma3 (allowed: "
                   "q_peak_sd_<unit>, eps_a_peak_sd_<unit>, q_end_sd_<unit>, max_dilatancy_sd, e_ini_sd_<unit>"),
            std::string::npos) << e;
  e = error_of("material,sigma3_kPa,q_peak_kPa,q_end_sd_kPa\nA,100,300,1\n");
  EXPECT_NE(e.find("bad.csv:1:q_end_sd_kPa: a standard deviation of q_end, which the file does not give"),
            std::string::npos) << e;
  e = error_of("material,sigma3_kPa,q_peak_kPa,q_peak_sd_kPa\nA,100,300,\n");
  EXPECT_NE(e.find("bad.csv:2:q_peak_sd_kPa: missing for part of a test"), std::string::npos) << e;
  e = error_of("material,sigma3_kPa,q_peak_kPa,q_peak_sd_psi\nA,100,300,1\n");
  EXPECT_NE(e.find("bad.csv:1:q_peak_sd_psi: unit 'psi' does not parse for q_peak_sd (allowed: MPa, Pa, kPa)"),
            std::string::npos) << e;
  e = error_of("material,sigma3_kPa,q_peak_kPa,q_peak_sd_kPa,q_peak_sd_MPa\nA,100,300,1,1\n");
  EXPECT_NE(e.find("bad.csv:1:q_peak_sd_MPa: column given twice"), std::string::npos) << e;
}

// The state after consolidation: one value per test, a porosity taken as a void ratio (e = n / (1 - n), its
// standard deviation through de/dn = 1 / (1 - n)^2).
TEST(Measured, VoidRatioOrPorosityIsOnePerTest) {
  const MeasuredData c = load_measured(write("curve_e.csv",
                                             "material,sigma3_kPa,eps_a_pct,q_kPa,void_ratio,void_ratio_sd\n"
                                             "A,100,0,0,0.65,0.02\nA,100,1,100,0.65,0.02\nA,100,2,90,0.65,0.02\n"
                                             "B,100,0,0,0.7,0.01\nB,100,1,80,0.7,0.01\nB,100,2,85,0.7,0.01\n"));
  ASSERT_EQ(c.tests.size(), 2u);
  EXPECT_DOUBLE_EQ(c.tests[0].void_ratio, 0.65);
  EXPECT_DOUBLE_EQ(c.tests[0].void_ratio_sd, 0.02);
  EXPECT_DOUBLE_EQ(c.tests[1].void_ratio, 0.7);
  const MeasuredData s = load_measured(write("summary_n.csv",
                                             "material,sigma3_kPa,q_peak_kPa,porosity,porosity_sd\n"
                                             "A,100,300,0.4,0.012\nA,200,500,0.375,0.01\n"));
  EXPECT_DOUBLE_EQ(s.tests[0].void_ratio, 0.4 / 0.6);
  EXPECT_DOUBLE_EQ(s.tests[0].void_ratio_sd, 0.012 / (0.6 * 0.6));
  EXPECT_DOUBLE_EQ(s.tests[1].void_ratio, 0.6);
  const MeasuredData none = load_measured(write("summary_none.csv", "material,sigma3_kPa,q_peak_kPa\nA,100,300\n"));
  EXPECT_TRUE(std::isnan(none.tests[0].void_ratio));
  EXPECT_TRUE(std::isnan(none.tests[0].void_ratio_sd));
}

TEST(Measured, BadVoidRatiosAreRefusedWithLineAndColumn) {
  std::string e = error_of("material,sigma3_kPa,q_peak_kPa,void_ratio,porosity\nA,100,300,0.6,0.4\n");
  EXPECT_NE(e.find("bad.csv:1:porosity: give void_ratio or porosity, not both"), std::string::npos) << e;
  e = error_of("material,sigma3_kPa,q_peak_kPa,void_ratio\nA,100,300,0\n");
  EXPECT_NE(e.find("bad.csv:2:void_ratio: void ratio must be in (0, 5]"), std::string::npos) << e;
  e = error_of("material,sigma3_kPa,q_peak_kPa,void_ratio\nA,100,300,5.5\n");
  EXPECT_NE(e.find("bad.csv:2:void_ratio: void ratio must be in (0, 5]"), std::string::npos) << e;
  e = error_of("material,sigma3_kPa,q_peak_kPa,porosity\nA,100,300,40\n");  // percent
  EXPECT_NE(e.find("bad.csv:2:porosity: porosity must be in (0, 1)"), std::string::npos) << e;
  e = error_of("material,sigma3_kPa,q_peak_kPa,porosity\nA,100,300,1\n");
  EXPECT_NE(e.find("bad.csv:2:porosity: porosity must be in (0, 1)"), std::string::npos) << e;
  const std::string curve = "material,sigma3_kPa,eps_a_pct,q_kPa,porosity,porosity_sd\nA,100,0,0,0.4,0.01\n";
  e = error_of(curve + "A,100,1,50,0.41,0.01\n");
  EXPECT_NE(e.find("bad.csv:3:porosity: '0.41' differs from the test's first row, "), std::string::npos) << e;
  EXPECT_NE(e.find("bad.csv:2 (one value per test"), std::string::npos) << e;
  e = error_of(curve + "A,100,1,50,0.4,0.02\n");
  EXPECT_NE(e.find("bad.csv:3:porosity_sd: '0.02' differs from the test's first row, "), std::string::npos) << e;
  e = error_of(curve + "A,100,1,50,0.4,0\n");
  EXPECT_NE(e.find("bad.csv:3:porosity_sd: standard deviation must be > 0"), std::string::npos) << e;
  e = error_of("material,sigma3_kPa,q_peak_kPa,porosity,void_ratio_sd\nA,100,300,0.4,0.01\n");
  EXPECT_NE(e.find("bad.csv:1:void_ratio_sd: a standard deviation of void_ratio, which the file does not give"),
            std::string::npos) << e;
}

// Tests are keyed by material, pressure and label: two labels at one pressure are two curves (each with its own
// increasing strain), and a summary may give a pressure once per label.
TEST(Measured, TestLabelsTellReplicatesApart) {
  const MeasuredData c = load_measured(write("replicates.csv",
                                             "material,sigma3_kPa,test,eps_a_pct,q_kPa\n"
                                             "A,100,r1,0,0\nA,100,r1,1,100\nA,100,r2,0,0\nA,100,r2,1,110\n"
                                             "A,100,r1,2,120\nA,100,r2,2,115\n"));
  ASSERT_EQ(c.tests.size(), 2u);
  EXPECT_EQ(c.tests[0].replicate, "r1");
  EXPECT_EQ(c.tests[1].replicate, "r2");
  EXPECT_EQ(c.tests[0].q, (std::vector<Real>{0, 100e3, 120e3}));
  EXPECT_EQ(c.tests[1].q, (std::vector<Real>{0, 110e3, 115e3}));
  EXPECT_EQ(replicate_groups(c.tests), (std::vector<std::vector<std::size_t>>{{0, 1}}));
  // The same pressure: nothing to tell but the q measure the file did not name.
  ASSERT_EQ(c.notes.size(), 1u);
  EXPECT_NE(c.notes[0].find("no q_measure column: q taken as fixed_area"), std::string::npos) << c.notes[0];
  const MeasuredData s = load_measured(write("replicates_summary.csv", "material,sigma3_kPa,test,q_peak_kPa\n"
                                                                        "A,100,1,300\nA,100,2,310\n"));
  ASSERT_EQ(s.tests.size(), 2u);
  EXPECT_EQ(s.tests[1].replicate, "2");
  const MeasuredData u = load_measured(write("unlabelled.csv", "material,sigma3_kPa,q_peak_kPa\nA,100,300\n"));
  EXPECT_TRUE(u.tests[0].replicate.empty());
  std::string e = error_of("material,sigma3_kPa,test,q_peak_kPa\nA,100,1,300\nA,100,2,310\nA,100,1,320\n");
  EXPECT_NE(e.find("bad.csv:4: material A at 100 kPa, test 1 given twice (first on "), std::string::npos) << e;
  e = error_of("material,sigma3_kPa,test,eps_a_pct,q_kPa\nA,100,r1,0,0\nA,100,r2,0,0\nA,100,r1,0,10\n");
  EXPECT_NE(e.find("bad.csv:4:eps_a_pct: axial strain must increase within a test (A at 100 kPa, test r1)"),
            std::string::npos) << e;
  // Issue 87: a whole curve given twice was refused as a strain that does not increase, at its first row again.
  e = error_of("material,sigma3_kPa,eps_a_pct,q_kPa\nA,100,0,0\nA,100,1,100\nA,100,2,120\nA,100,0,0\nA,100,1,100\n");
  EXPECT_NE(e.find("bad.csv:5:eps_a_pct: 0% starts the curve of A at 100 kPa again (its first row: 0%): a test given "
                   "twice; replicates need a test column, a label each"), std::string::npos) << e;
}

// Implausible values are refused: a deviator beyond 100 sigma3 (q = -3e9 kPa was once accepted), a strain
// beyond 100%, a negative initial stiffness; the limits themselves are accepted.
TEST(Measured, ImplausibleValuesAreRefusedWithLineAndColumn) {
  const std::string curve = "material,sigma3_kPa,eps_a_pct,q_kPa,eps_v_pct\nA,100,0,0,0\n";
  std::string e = error_of(curve + "A,100,1,-3e9,0\n");
  EXPECT_NE(e.find("bad.csv:3:q_kPa: -3e+09 kPa is implausible at sigma3 = 100 kPa (allowed: |q| <= 100 sigma3 = "
                   "10000 kPa)"),
            std::string::npos) << e;
  e = error_of(curve + "A,100,150,50,0\n");
  EXPECT_NE(e.find("bad.csv:3:eps_a_pct: 150% is implausible (allowed: |eps_a| <= 100%)"), std::string::npos) << e;
  e = error_of(curve + "A,100,1,50,-101\n");
  EXPECT_NE(e.find("bad.csv:3:eps_v_pct: -101% is implausible (allowed: |eps_v| <= 100%)"), std::string::npos) << e;
  const TriaxialTest edge =
      load_measured(write("edge.csv", curve + "A,100,50,5000,-50\nA,100,100,10000,-100\n")).tests[0];
  EXPECT_DOUBLE_EQ(edge.q.back(), 100 * 100e3);
  const std::string summary =
      "material,sigma3_kPa,q_peak_kPa,eps_a_peak_pct,q_end_kPa,e_ini_MPa,q_1pct_kPa,q_3pct_kPa\n";
  e = error_of(summary + "A,100,10001,5,200,50,100,150\n");
  EXPECT_NE(e.find("bad.csv:2:q_peak_kPa: 10001 kPa is implausible at sigma3 = 100 kPa (allowed: |q_peak| <= "),
            std::string::npos) << e;
  e = error_of(summary + "A,100,300,101,200,50,100,150\n");
  EXPECT_NE(e.find("bad.csv:2:eps_a_peak_pct: 101% is implausible (allowed: |eps_a_peak| <= 100%)"), std::string::npos)
      << e;
  e = error_of(summary + "A,100,300,5,-20000,50,100,150\n");
  EXPECT_NE(e.find("bad.csv:2:q_end_kPa: -20000 kPa is implausible"), std::string::npos) << e;
  e = error_of(summary + "A,100,300,5,200,-50,100,150\n");
  EXPECT_NE(e.find("bad.csv:2:e_ini_MPa: initial stiffness must be >= 0"), std::string::npos) << e;
  e = error_of(summary + "A,100,300,5,200,inf,100,150\n");
  EXPECT_NE(e.find("bad.csv:2:e_ini_MPa: 'inf' is not a number"), std::string::npos) << e;
  e = error_of(summary + "A,100,300,5,200,50,1e5,150\n");
  EXPECT_NE(e.find("bad.csv:2:q_1pct_kPa: 100000 kPa is implausible"), std::string::npos) << e;
  e = error_of(summary + "A,100,300,5,200,50,100,0.011e6\n");
  EXPECT_NE(e.find("bad.csv:2:q_3pct_kPa: 11000 kPa is implausible"), std::string::npos) << e;
  // Issue 87: 480.5 particles were accepted without a word.
  const std::string sized = "material,sigma3_kPa,q_peak_kPa,specimen_balls\n";
  e = error_of(sized + "A,100,300,480.5\n");
  EXPECT_NE(e.find("bad.csv:2:specimen_balls: particles in the specimen: a whole number in [1, 1e12]"),
            std::string::npos) << e;
  EXPECT_DOUBLE_EQ(load_measured(write("sized.csv", sized + "A,100,300,480\n")).tests[0].specimen_balls, 480);
}

// What no drained test shows is refused, naming the file, the test and what is allowed (issue 65): sigma3 in Pa
// under a kPa header (the peak 0.0014 of it, where 0.05 is a friction angle of 1.4 deg), a peak at or below zero (every
// q negative, a summary q_peak of -5 kPa, q zero throughout), eps_v zero on every row, a negative axial strain, and
// curve and summary columns in one file. A peak of exactly 0.05 sigma3 is accepted: the bound is the bound.
TEST(Measured, WhatNoDrainedTestShowsIsRefused) {
  const std::string curve = "material,sigma3_kPa,eps_a_pct,q_kPa,eps_v_pct\n";
  std::string e = error_of(curve + "A,100000,0,0,0\nA,100000,1,120,0.1\nA,100000,2,142,0.2\n");
  // The peak is the smoothed curve's (a moving mean over +-0.25% strain), 120 kPa on these rows.
  EXPECT_NE(e.find("bad.csv: A at 100000 kPa: the peak of its q 120 kPa is 0.0012 of sigma3 (allowed: at least 0.05 "
                   "sigma3"), std::string::npos) << e;
  EXPECT_NE(e.find("is sigma3 in Pa under a kPa header"), std::string::npos) << e;
  e = error_of(curve + "A,100,0,-1,0\nA,100,1,-120,0.1\nA,100,2,-142,0.2\n");
  EXPECT_NE(e.find("bad.csv: A at 100 kPa: the peak of its q is -120 kPa"), std::string::npos) << e;
  EXPECT_NE(e.find("(compression positive; allowed: q_peak > 0)"), std::string::npos) << e;
  e = error_of(curve + "A,100,0,0,0\nA,100,1,0,0\nA,100,2,0,0\n");
  EXPECT_NE(e.find("the peak of its q is 0 kPa"), std::string::npos) << e;
  e = error_of(curve + "A,100,0,0,0\nA,100,1,120,0\nA,100,2,142,0\n");
  EXPECT_NE(e.find("bad.csv: A at 100 kPa: eps_v is zero on every row"), std::string::npos) << e;
  e = error_of(curve + "A,100,-0.5,0,0\nA,100,1,120,0.1\nA,100,2,142,0.2\n");
  EXPECT_NE(e.find("bad.csv:2:eps_a_pct: -0.5%: axial strain is >= 0"), std::string::npos) << e;
  e = error_of("material,sigma3_kPa,q_peak_kPa\nA,100,-5\n");
  EXPECT_NE(e.find("bad.csv: A at 100 kPa: q_peak is -5 kPa"), std::string::npos) << e;
  e = error_of("material,sigma3_kPa,eps_a_pct,q_kPa,q_peak_kPa\nA,100,0,0,300\n");
  EXPECT_NE(e.find("bad.csv:1:q_peak_kPa: q_peak is a summary column"), std::string::npos) << e;
  EXPECT_DOUBLE_EQ(load_measured(write("low.csv", "material,sigma3_kPa,q_peak_kPa\nA,100,5\n")).tests[0].q_peak, 5e3);
}

// Files that are no UTF-8 text printed their raw bytes as a column's name ("\xff\xfem", "\x89HDF: unknown column"),
// an empty header cell showed no name, a quoted cell with a comma only a cell count (issue 65, item 18): each now says
// what the file is and how to write it.
TEST(Measured, WhatIsNoCsvTextSaysWhatItIs) {
  std::string e = error_of(std::string("\xFF\xFEm\0a\0", 6));
  EXPECT_NE(e.find("bad.csv: UTF-16 text (allowed: UTF-8 or ASCII): save it as UTF-8"), std::string::npos) << e;
  e = error_of(std::string("\x89HDF\r\n\x1a\n\0\0", 10));
  EXPECT_NE(e.find("bad.csv: an HDF5 file under another name"), std::string::npos) << e;
  EXPECT_NE(e.find("rename it to .h5"), std::string::npos) << e;
  e = error_of(std::string("mat\0rial\n", 10));
  EXPECT_NE(e.find("bad.csv: not text (a NUL byte"), std::string::npos) << e;
  e = error_of("material,sigma3_kPa,q_peak_kPa,\nA,100,120,\n");
  EXPECT_NE(e.find("a column without a name: a comma at the end of the header"), std::string::npos) << e;
  e = error_of("material,sigma3_kPa,q_peak_kPa\n\"beads, rough\",100,120\n");
  EXPECT_NE(e.find("has 4 cells, the header 3 (quotes are not read"), std::string::npos) << e;
  // A spreadsheet's UTF-8 byte order mark is still read past.
  const std::string bom = write("bom.csv", "\xEF\xBB\xBFmaterial,sigma3_kPa,q_peak_kPa\nA,100,120\n");
  EXPECT_EQ(load_measured(bom).tests.size(), 1u);
}

// Pressures within 2% of a group's first test are one pressure: grouped, each test once, groups in order of
// their first test; the reader says so when they are not exactly equal.
TEST(Measured, NearEqualPressuresAreGroupedAsReplicates) {
  auto test = [](const std::string& m, Real s) {
    TriaxialTest t;
    t.material = m;
    t.sigma3 = s;
    return t;
  };
  const std::vector<TriaxialTest> tests = {test("A", 100e3), test("B", 100e3), test("A", 200e3), test("A", 101e3),
                                           test("A", 102.5e3), test("B", 99e3), test("A", 100e3)};
  // 102.5 is within 2% of 101 but not of 100, the group's first: it stands alone.
  EXPECT_EQ(replicate_groups(tests), (std::vector<std::vector<std::size_t>>{{0, 3, 6}, {1, 5}, {2}, {4}}));
  EXPECT_TRUE(replicate_groups({}).empty());
  const MeasuredData d = load_measured(write("near.csv", "material,sigma3_kPa,q_peak_kPa\n"
                                                         "A,100,300\nA,101,305\nA,200,500\nB,100,310\nB,300,700\n"));
  ASSERT_EQ(d.tests.size(), 5u);
  ASSERT_EQ(d.notes.size(), 2u);  // and the q measure taken
  EXPECT_NE(d.notes[0].find("near.csv: material A: tests at 100 and 101 kPa differ by less than 2%: taken as "
                            "replicates of one pressure"),
            std::string::npos) << d.notes[0];
}

TEST(Measured, UnknownColumnErrorListsTheOptionalColumns) {
  const std::string e = error_of("material,sigma3_kPa,q_peak_kPa,density\nA,100,300,1\n");
  EXPECT_NE(e.find("bad.csv:1:density: unknown column (allowed: material, test, sigma3_<unit>"), std::string::npos) << e;
  for (const char* c :
       {"<quantity>_sd_<unit>", "max_dilatancy_sd", "void_ratio or porosity", "void_ratio_sd", "porosity_sd"})
    EXPECT_NE(e.find(c), std::string::npos) << c << " in " << e;
}

// The HDF5 form goes through the same parser: a label (a number there), standard deviations and a void ratio.
TEST(Measured, Hdf5FormCarriesTheOptionalColumns) {
  const std::string h5 = write("optional.h5", "");
  write_measured_h5(h5, {"sigma3_kPa", "test", "eps_a_pct", "q_kPa", "q_sd_kPa", "void_ratio"},
                    {{"A",
                      {{100, 1, 0, 0, 2, 0.6}, {100, 1, 1, 90, 3, 0.6}, {100, 1, 2, 92, 3, 0.6},
                       {100, 2, 0, 0, 2, 0.62}, {100, 2, 1, 95, 4, 0.62}, {100, 2, 2, 97, 5, 0.62}}}},
                    "test");
  const MeasuredData d = load_measured(h5);
  ASSERT_EQ(d.tests.size(), 2u);
  EXPECT_EQ(d.tests[1].replicate, "2");
  EXPECT_EQ(d.tests[1].q_sd, (std::vector<Real>{2e3, 4e3, 5e3}));
  EXPECT_DOUBLE_EQ(d.tests[1].void_ratio, 0.62);
  write_measured_h5(h5, {"sigma3_kPa", "eps_a_pct", "q_kPa", "q_sd_kPa"}, {{"A", {{100, 0, 0, 2}, {100, 1, 90, 0}}}},
                    "test");
  try {
    load_measured(h5);
    ADD_FAILURE() << "accepted a zero standard deviation";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("optional.h5:/A/table row 2:q_sd_kPa: standard deviation must be > 0"),
              std::string::npos) << e.what();
  }
}

// Which q the lab reported: a column with one name for the whole file (an attribute in HDF5), fixed_area with a
// note when the file does not say; an unknown name or a second one is refused with line and column.
TEST(Measured, TheFileSaysWhichQTheLabReported) {
  const MeasuredData a = load_measured(write("measure.csv", "material,sigma3_kPa,q_peak_kPa,q_measure\n"
                                                            "A,100,300,area_corrected\nA,200,500,area_corrected\n"));
  EXPECT_TRUE(a.q_measure_given);
  EXPECT_EQ(a.q_measure, QMeasure::kAreaCorrected);
  EXPECT_TRUE(a.notes.empty());
  const MeasuredData b = load_measured(write("no_measure.csv", "material,sigma3_kPa,q_peak_kPa\nA,100,300\n"));
  EXPECT_FALSE(b.q_measure_given);
  EXPECT_EQ(b.q_measure, QMeasure::kFixedArea);
  ASSERT_EQ(b.notes.size(), 1u);
  EXPECT_NE(b.notes[0].find("no_measure.csv: no q_measure column: q taken as fixed_area"), std::string::npos);
  std::string e = error_of("material,sigma3_kPa,q_peak_kPa,q_measure\nA,100,300,corrected\n");
  EXPECT_NE(e.find("bad.csv:2:q_measure: 'corrected' is not a q measure (allowed: fixed_area, area_corrected, "
                   "parabolic, membrane_corrected)"),
            std::string::npos) << e;
  e = error_of("material,sigma3_kPa,q_peak_kPa,q_measure\nA,100,300,parabolic\nA,200,500,fixed_area\n");
  EXPECT_NE(e.find("bad.csv:3:q_measure: 'fixed_area' differs from the first row's 'parabolic'"), std::string::npos)
      << e;
  const std::string h5 = write("measure.h5", "");
  write_measured_h5(h5, {"sigma3_kPa", "q_peak_kPa"}, {{"A", {{100, 300}}}}, "test", "membrane_corrected");
  const MeasuredData c = load_measured(h5);
  EXPECT_EQ(c.q_measure, QMeasure::kMembraneCorrected);
  write_measured_h5(h5, {"sigma3_kPa", "q_peak_kPa"}, {{"A", {{100, 300}}}}, "test", "wrong");
  try {
    load_measured(h5);
    ADD_FAILURE() << "accepted an unknown q measure";
  } catch (const DataError& x) {
    EXPECT_NE(std::string(x.what()).find("measure.h5:/A/table row 1:q_measure: 'wrong' is not a q measure"),
              std::string::npos) << x.what();
  }
}

// A spreadsheet's CSV starts with a UTF-8 byte order mark, which made the first column "unknown column material";
// a device is refused by name instead of read without end.
TEST(Measured, AByteOrderMarkIsNoPartOfTheHeaderAndADeviceIsNoData) {
  const MeasuredData d = load_measured(write("bom.csv", "\xEF\xBB\xBFmaterial,sigma3_kPa,q_peak_kPa\nA,100,300\n"));
  ASSERT_EQ(d.tests.size(), 1u);
  EXPECT_EQ(d.tests[0].material, "A");
  try {
    load_measured("/dev/zero");
    ADD_FAILURE() << "read a device";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/zero: not a regular file"), std::string::npos) << e.what();
  }
}

// The Mohr-Coulomb friction angle of a drained triaxial test, sin(phi) = (sigma1 - sigma3) / (sigma1 + sigma3):
// q = 2 sigma3 gives sigma1 = 3 sigma3 and sin(phi) = 1/2, 30 degrees; q = 0 none; q = 8 sigma3 gives 4/5
// (53.13 degrees). The study's tables rest on this function.
TEST(Measured, FrictionAngleOfTheTriaxialTestIsMohrCoulombs) {
  EXPECT_NEAR(friction_angle_deg(200e3, 100e3), 30.0, 1e-12);
  EXPECT_NEAR(friction_angle_deg(0, 100e3), 0.0, 1e-12);
  EXPECT_NEAR(friction_angle_deg(800e3, 100e3), std::asin(0.8) * 180 / M_PI, 1e-12);
  EXPECT_NEAR(friction_angle_deg(2, 1), 30.0, 1e-12) << "a ratio: the unit does not matter";
}

// A file with one point per test started a calibration, its peak and stiffness read off single points: a curve
// needs three rows per test, and the message says where the one-row form belongs (a summary file).
TEST(Measured, ACurveOfOneOrTwoRowsIsRefused) {
  std::string e = error_of("material,sigma3_kPa,eps_a_pct,q_kPa\nA,100,1,50\nA,200,0,0\nA,200,1,80\nA,200,2,90\n");
  EXPECT_NE(e.find("bad.csv: A at 100 kPa: 1 row (allowed: at least 3 rows of eps_a and q per test: a curve; give "
                   "one row per test in a summary file"), std::string::npos) << e;
  e = error_of("material,sigma3_kPa,eps_a_pct,q_kPa\nA,100,0,0\nA,100,1,50\n");
  EXPECT_NE(e.find(": 2 rows (allowed: at least 3"), std::string::npos) << e;
  EXPECT_EQ(error_of("material,sigma3_kPa,eps_a_pct,q_kPa\nA,100,0,0\nA,100,1,50\nA,100,2,40\n"), "");
}

// A measured file of 10^6 rows spent minutes smoothing before any check or message: a test's rows are capped, and
// the cap names the count, the limit and a thinning that fits.
TEST(Measured, ACurveOfMoreRowsThanTheCapIsRefused) {
  const auto curve = [](long rows) {
    std::string text = "material,sigma3_kPa,eps_a_pct,q_kPa\n";
    for (long k = 0; k < rows; ++k)
      text += "A,100," + std::to_string(15.0 * k / rows) + "," + std::to_string(100.0 + (k % 7)) + "\n";
    return text;
  };
  const std::string e = error_of(curve(100001));
  EXPECT_NE(e.find("bad.csv: A at 100 kPa: 100001 rows (allowed: at most 100000 per test"), std::string::npos) << e;
  EXPECT_NE(e.find("thin it, e.g. every 20th row"), std::string::npos) << e;
  EXPECT_EQ(error_of(curve(100000)), "");
}

// Compression files (host/data/compression_data.hpp): the test named by test_type, a test the rows of one material,
// type and seating stress in file order, units to SI.
TEST(Measured, CompressionFilesGroupTheirIncrementsByTest) {
  const std::vector<CompressionTest> t = load_compression(write("oedometer.csv",
      "# two tests\nmaterial,test_type,sigma3_kPa,stress_MPa,strain_pct,K0\n"
      "S-1,oedometer,100,0.2,0.10,0.45\nS-1,oedometer,100,0.4,0.25,0.44\nS-1,oedometer,100,0.2,0.20,0.60\n"
      "S-2,oedometer,50,0.2,0.30,0.41\n"));
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[0].material, "S-1");
  EXPECT_EQ(t[0].path, CompressionPath::oedometer);
  EXPECT_DOUBLE_EQ(t[0].sigma3, 100e3);
  ASSERT_EQ(t[0].stress.size(), 3u);  // loading and unloading, as the lab went
  EXPECT_DOUBLE_EQ(t[0].stress[1], 400e3);
  EXPECT_DOUBLE_EQ(t[0].strain[1], 0.0025);
  EXPECT_DOUBLE_EQ(t[0].k0[2], 0.60);
  EXPECT_TRUE(t[0].strain_sd.empty());
  EXPECT_DOUBLE_EQ(t[1].sigma3, 50e3);
  const std::vector<CompressionTest> iso = load_compression(write("isotropic.csv",
      "material,test_type,sigma3_Pa,stress_kPa,strain_frac,strain_sd_pct\nA,isotropic,1e5,200,0.004,0.05\n"));
  ASSERT_EQ(iso.size(), 1u);
  EXPECT_EQ(iso[0].path, CompressionPath::isotropic);
  EXPECT_DOUBLE_EQ(iso[0].strain_sd[0], 5e-4);
}

TEST(Measured, BadCompressionFilesAreRefusedWithLineAndColumn) {
  auto error = [](const std::string& text) {
    try {
      load_compression(write("bad_compression.csv", text));
    } catch (const DataError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string head = "material,test_type,sigma3_kPa,stress_kPa,strain_pct\n";
  EXPECT_NE(error(head + "S-1,triaxial,100,200,0.1\n").find("bad_compression.csv:2:test_type: compression test "
                                                             "'triaxial': allowed: oedometer, isotropic"),
            std::string::npos);
  EXPECT_NE(error(head + "S-1,oedometer,100,-200,0.1\n").find(":2:stress_kPa: '-200' is out of range"), std::string::npos);
  EXPECT_NE(error(head + "S-1,oedometer,100,200,abc\n").find(":2:strain_pct: 'abc' is not a number"), std::string::npos);
  EXPECT_NE(error("material,test_type,sigma3_kPa,stress_kPa\nS-1,oedometer,100,200\n").find("missing column 'strain'"),
            std::string::npos);
  EXPECT_NE(error("material,test_type,sigma3_kPa,stress_psi,strain_pct\n").find("stress_psi: unit 'psi'"),
            std::string::npos);
  EXPECT_NE(error("material,test_type,sigma3_kPa,stress_kPa,strain_pct,e\n").find("e: unknown column"),
            std::string::npos);
  EXPECT_NE(error("material,test_type,sigma3_kPa,stress_kPa,strain_pct,K0\nS-1,isotropic,100,200,0.1,0.5\n")
                .find(":2:K0: an isotropic test has no K0"), std::string::npos);
  EXPECT_NE(error(head).find("no rows"), std::string::npos);
}
