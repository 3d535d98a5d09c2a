// The study command's pieces: which job runs a config, and the summary file each job leaves behind.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <cmath>
#include <fstream>
#include <limits>
#include <tuple>

#include "host/cli/job.hpp"
#include "host/study/study.hpp"
#include "host/util/process_pool.hpp"
#include "test_util.hpp"

using namespace dem;

namespace {
constexpr Real kNaNForTest = std::numeric_limits<Real>::quiet_NaN();
}

TEST(Study, ThePaperFolderHoldsNineMembraneCases) {
  const auto cases = study_cases({std::string(TRIAXDEM_SOURCE_DIR) + "/configs/paper"});
  ASSERT_EQ(cases.size(), 9u);
  EXPECT_EQ(cases.front().name, "S1_100kPa");
  EXPECT_EQ(cases.back().name, "S3_300kPa");
  for (const StudyCase& c : cases) {
    EXPECT_EQ(c.job, "triaxial") << c.config;
    EXPECT_EQ(c.material, "S-" + c.name.substr(1, 1)) << c.config;  // Table 6's sample, for study --compare
  }
  const auto periodic = study_cases({std::string(TRIAXDEM_SOURCE_DIR) + "/configs/periodic"});
  for (const StudyCase& c : periodic) EXPECT_EQ(c.job, "periodic") << c.config;
}

TEST(Study, ConfigWithoutATestIsRefusedByName) {
  try {
    study_cases({std::string(TRIAXDEM_SOURCE_DIR) + "/configs/default.toml"});
    FAIL() << "the default config is a settling box, not a triaxial test";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("default.toml"), std::string::npos) << e.what();
  }
  EXPECT_THROW(study_cases({"/nonexistent/folder"}), std::runtime_error);
}

// A study into a triaxial run's own folder mixed its cases' files with the run's (issue 65): refused before any case.
TEST(Study, ARunsFolderIsNoStudysOutput) {
  const auto dir = dem::test::scratch_dir("study_into_run");
  std::ofstream(dir / "summary.csv") << "q_peak_kPa\n100\n";
  StudyOptions opt;
  opt.output = dir.string();
  try {
    study_job({std::string(TRIAXDEM_SOURCE_DIR) + "/tests/data/tiny_triaxial.toml"}, opt, "/nonexistent");
    FAIL() << "a study into a run's folder";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(": a run's folder (summary.csv in it)"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "tiny_triaxial")) << "a case ran";
}

TEST(Study, SummaryRoundTripsInFileUnits) {
  const auto dir = dem::test::scratch_dir("study");
  TestSummary s;
  s.kind = "membrane";
  s.sigma3 = 200e3;
  s.mu_s = 0.3;
  s.mu_r = 0.02;
  s.balls = 3662;
  s.q_peak = 403.71e3;
  s.phi_peak_deg = 30.5;
  s.eps_a_peak = 0.042;
  s.max_dilatancy = 0.61;
  // Where it came from (a summary did not say): a comma in a path stays in one cell.
  s.provenance = {"0.1.0+abc1234-dirty", "OpenMP x2", "configs/a,b.toml", "0123456789abcdef", 17};
  write_summary(dir.string(), s);
  std::ifstream f(dir / "summary.csv");
  std::string header, row;
  std::getline(f, header);
  std::getline(f, row);
  EXPECT_NE(header.find("q_peak_kPa"), std::string::npos);
  EXPECT_NE(row.find("403.71"), std::string::npos) << row;  // kPa in the file
  const TestSummary r = read_summary((dir / "summary.csv").string());
  EXPECT_EQ(r.kind, "membrane");
  EXPECT_EQ(r.balls, 3662);
  EXPECT_NEAR(r.q_peak, 403.71e3, 1e-3);  // 6 significant digits in the file
  EXPECT_NEAR(r.eps_a_peak, 0.042, 1e-9);
  EXPECT_EQ(r.provenance.version, "0.1.0+abc1234-dirty");
  EXPECT_EQ(r.provenance.backend, "OpenMP x2");
  EXPECT_EQ(r.provenance.config, "configs/a;b.toml");
  EXPECT_EQ(r.provenance.config_hash, "0123456789abcdef");
  EXPECT_EQ(r.provenance.seed, 17);
  std::ofstream(dir / "broken.csv") << "kind,balls\nmembrane,3\n";
  try {
    read_summary((dir / "broken.csv").string());
    FAIL() << "columns are missing";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("wall_s"), std::string::npos) << e.what();
  }
}

// `study --resume`: a case that left a summary.csv is kept as it is (its value below is not one a run could
// produce, so seeing it proves the case did not run again), the other runs; without --resume both run.
TEST(Study, ResumeKeepsFinishedCasesAndRunsTheRest) {
  const auto dir = dem::test::scratch_dir("study_resume");
  std::filesystem::create_directories(dir / "configs");
  for (const char* name : {"a", "b"})
    std::filesystem::copy_file(std::string(TRIAXDEM_SOURCE_DIR) + "/tests/data/hidden_effects.toml",
                               dir / "configs" / (std::string(name) + ".toml"));
  StudyOptions opt;
  opt.output = (dir / "out").string();
  opt.workers = 1;
  opt.threads = 1;
  opt.resume = true;
  TestSummary done;
  done.kind = "periodic";
  done.q_peak = 12345e3;
  std::filesystem::create_directories(dir / "out" / "a");
  write_summary((dir / "out" / "a").string(), done);
  ASSERT_EQ(study_job({(dir / "configs").string()}, opt, dem::test::triaxdem_binary().c_str()), 0);
  EXPECT_NEAR(read_summary((dir / "out" / "a" / "summary.csv").string()).q_peak, 12345e3, 1);
  const double b = read_summary((dir / "out" / "b" / "summary.csv").string()).q_peak;
  EXPECT_GT(b, 10e3);
  EXPECT_LT(b, 1000e3);
  std::ifstream table(dir / "out" / "study_summary.csv");
  const std::string text((std::istreambuf_iterator<char>(table)), {});
  EXPECT_NE(text.find("12345"), std::string::npos) << text;
}

// The table a study rewrites after every case: finished cases with their values, the others marked pending
// or failed, so a study stopped half-way leaves a table of what it finished.
TEST(Study, TableMarksPendingAndFailedCases) {
  const auto dir = dem::test::scratch_dir("study_table");
  std::vector<StudyCase> cases(3);
  const char* names[] = {"done", "waiting", "broken"};
  for (std::size_t k = 0; k < cases.size(); ++k) {
    cases[k].name = names[k];
    cases[k].config = std::string(names[k]) + ".toml";
    cases[k].job = "triaxial";
    cases[k].material = "S-1";
  }
  TestSummary done;
  done.kind = "membrane";
  done.sigma3 = 100e3;
  done.q_peak = 150e3;
  std::filesystem::create_directories(dir / "done");
  write_summary((dir / "done").string(), done);
  MeasuredData lab;
  lab.path = "lab.csv";
  TriaxialTest t;
  t.material = "S-1";
  t.sigma3 = 100e3;
  t.q_peak = 120e3;
  lab.tests.push_back(t);
  const StudyTable table = study_table(cases, {0, -1, 2}, dir.string(), {lab});
  EXPECT_TRUE(table.ok[0]);
  EXPECT_FALSE(table.ok[1]);
  EXPECT_FALSE(table.ok[2]);
  EXPECT_NE(table.csv.find("done,done.toml,triaxial,ok,S-1,"), std::string::npos) << table.csv;
  EXPECT_NE(table.csv.find(",120.00,25.00\n"), std::string::npos) << table.csv;  // (150 - 120) / 120
  EXPECT_NE(table.csv.find("waiting,waiting.toml,triaxial,pending,S-1\n"), std::string::npos) << table.csv;
  EXPECT_NE(table.csv.find("broken,broken.toml,triaxial,failed,S-1\n"), std::string::npos) << table.csv;
  EXPECT_EQ(table.cmp[0].matched, 1);
}

// study --compare: cases are matched by material and sigma3; the error is relative to the measured peak, the mean
// and the largest over the matched cases only (an unmatched material, an absent pressure and a failed case are
// left out, not counted as zero error).
TEST(Study, PeaksAreComparedByMaterialAndPressure) {
  MeasuredData d;
  d.path = "lab.csv";
  for (const auto& [material, sigma3, q] : std::vector<std::tuple<std::string, Real, Real>>{
           {"S-1", 100e3, 140e3}, {"S-1", 200e3, 250e3}, {"S-2", 100e3, 200e3}}) {
    TriaxialTest t;
    t.material = material;
    t.sigma3 = sigma3;
    t.q_peak = q;
    d.tests.push_back(t);
  }
  std::vector<StudyCase> cases(5);
  std::vector<TestSummary> s(5);
  const std::vector<std::tuple<std::string, Real, Real>> runs = {
      {"S-1", 200e3, 260e3},  // +4%
      {"S-2", 100e3, 180e3},  // -10%
      {"S-3", 100e3, 1e3},    // no such material in the file
      {"S-1", 300e3, 1e3},    // no such pressure
      {"S-1", 100e3, kNaNForTest}};  // failed
  for (std::size_t k = 0; k < cases.size(); ++k) {
    cases[k].material = std::get<0>(runs[k]);
    s[k].sigma3 = std::get<1>(runs[k]);
    s[k].q_peak = std::get<2>(runs[k]);
  }
  const PeakComparison c = compare_peaks(d, cases, s);
  EXPECT_EQ(c.matched, 2);
  EXPECT_NEAR(c.error[0], 0.04, 1e-12);
  EXPECT_NEAR(c.error[1], -0.10, 1e-12);
  for (std::size_t k : {2, 3, 4}) EXPECT_TRUE(std::isnan(c.error[k])) << k;
  EXPECT_NEAR(c.measured[4], 140e3, 1e-9);  // the lab value is shown beside a failed case too
  EXPECT_NEAR(c.mean_abs_error, 0.07, 1e-12);
  EXPECT_NEAR(c.max_abs_error, 0.10, 1e-12);
  EXPECT_EQ(c.worst, 1u);
}

// Like with like: a file that says its q is area-corrected is compared with the cases' area-corrected peak;
// a periodic cell's one q stands for every measure (it has no boundary), also in a summary read back; a
// membrane summary written before the measures were recorded has none to compare.
TEST(Study, PeaksAreComparedInTheMeasureTheDataReport) {
  const auto dir = dem::test::scratch_dir("study_measure");
  MeasuredData d;
  d.path = "lab.csv";
  d.q_measure = QMeasure::kAreaCorrected;
  TriaxialTest t;
  t.material = "S-1";
  t.sigma3 = 100e3;
  t.q_peak = 120e3;
  d.tests.push_back(t);
  std::vector<StudyCase> cases(3);
  for (StudyCase& c : cases) c.material = "S-1";
  std::vector<TestSummary> s(3);
  for (TestSummary& x : s) x.sigma3 = 100e3;
  s[0].kind = "membrane";
  s[0].q_peak = 150e3;       // the platen force over the area after consolidation
  s[0].q_peak_area = 126e3;  // over the right cylinder's: +5% against the lab's 120
  s[1].kind = "periodic";
  s[1].q_peak = 90e3;
  write_summary(dir.string(), s[1]);
  s[1] = read_summary((dir / "summary.csv").string());
  s[2].kind = "membrane";
  s[2].q_peak = 150e3;
  s[2].q_peak_area = kNaNForTest;
  const PeakComparison c = compare_peaks(d, cases, s);
  EXPECT_EQ(c.measure, QMeasure::kAreaCorrected);
  EXPECT_NEAR(c.error[0], 0.05, 1e-12);
  EXPECT_NEAR(c.error[1], -0.25, 1e-6);  // 90 against 120
  EXPECT_TRUE(std::isnan(c.error[2]));
  EXPECT_EQ(c.matched, 2);
}

// A kept case's curve values come from its series.csv through the same summary as measured curves: rows that
// alternate by +-8 kPa about 100 kPa have a raw maximum of 108 kPa, but a moving-mean peak within 2 kPa of 100.
TEST(Study, KeptCasesAreSummarisedAfreshFromTheirSeries) {
  const auto dir = dem::test::scratch_dir("study_series");
  {
    std::ofstream f(dir / "series.csv");
    f << "eps_a_pct,q_kPa,sigma3_kPa,eps_v_pct\n";
    for (int k = 0; k <= 50; ++k)
      f << 0.1 * k << "," << (k == 0 ? 0.0 : 100.0 + (k % 2 ? 8.0 : -8.0)) << ",100," << -0.02 * k << "\n";
  }
  TestSummary s;
  s.sigma3 = 100e3;
  s.q_peak = 999e3;
  ASSERT_TRUE(summarise_series(dir.string(), s));
  EXPECT_GT(s.q_peak, 98e3);
  EXPECT_LT(s.q_peak, 102e3);
  EXPECT_NEAR(s.max_dilatancy, 0.2, 1e-9);  // eps_v = -0.2 eps_a
  EXPECT_NEAR(s.phi_peak_deg, friction_angle_deg(s.q_peak, 100e3), 1e-12);
  TestSummary untouched;
  untouched.q_peak = 7;
  EXPECT_FALSE(summarise_series((dir / "nothing_here").string(), untouched));
  EXPECT_EQ(untouched.q_peak, 7);
}

// The study starts its longest cases first (process_pool.hpp's start_order, by study_case_cost). At one inertial
// number a case's shear takes steps as 1/sqrt(sigma3): the paper's S-1 cases took 65 min at 100 kPa and 34 at
// 300 kPa on 2 threads (docs/history/performance.md), so a 100 kPa case must come before any 300 kPa case, and the
// estimate's ratio is sqrt(3) for the same specimen. Without a cost the pieces start in index order.
TEST(Study, LongestCasesStartFirst) {
  const auto cases = study_cases({std::string(TRIAXDEM_SOURCE_DIR) + "/configs/paper"});
  PoolWork w;
  w.pieces = cases.size();
  std::vector<std::size_t> plain = start_order(w);
  for (std::size_t k = 0; k < plain.size(); ++k) EXPECT_EQ(plain[k], k);
  w.cost = [&](std::size_t k) { return cases[k].cost; };
  const std::vector<std::size_t> order = start_order(w);
  ASSERT_EQ(order.size(), 9u);
  EXPECT_NE(cases[order.front()].name.find("100kPa"), std::string::npos) << cases[order.front()].name;
  EXPECT_NE(cases[order.back()].name.find("300kPa"), std::string::npos) << cases[order.back()].name;
  for (std::size_t k = 1; k < order.size(); ++k) EXPECT_GE(cases[order[k - 1]].cost, cases[order[k]].cost);
  // S1_100kPa is case 0 and S1_300kPa case 2 (name order): the same specimen at three times the pressure.
  EXPECT_NEAR(cases[0].cost / cases[2].cost, std::sqrt(3.0), 1e-9);
}

// A study case of a minute printed nothing between "started" and "finished" (issue 65): while no piece ends, the pool
// calls `waiting` for each running one every waiting_seconds. A child that sleeps 2.5 s under a 1 s period is
// reported twice (at 1 and 2 s; up to 3 on a loaded machine).
TEST(Study, ALongPieceIsReportedWhileItRuns) {
  PoolWork w;
  w.pieces = 1;
  w.child = [](std::size_t, int) { ::usleep(2500000); };
  std::vector<std::size_t> seen;
  w.waiting = [&](std::size_t k) { seen.push_back(k); };
  w.waiting_seconds = 1;
  run_pool_here(w, "test");
  EXPECT_GE(seen.size(), 2u);
  EXPECT_LE(seen.size(), 3u);
  for (std::size_t k : seen) EXPECT_EQ(k, 0u);
}
