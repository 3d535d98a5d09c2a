// The study command's pieces: which job runs a config, and the summary file each job leaves behind.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "host/study.hpp"

#include <unistd.h>

using namespace dem;

TEST(Study, ThePaperFolderHoldsNineMembraneCases) {
  const auto cases = study_cases({std::string(TRIAXDEM_SOURCE_DIR) + "/configs/paper"});
  ASSERT_EQ(cases.size(), 9u);
  EXPECT_EQ(cases.front().name, "S1_100kPa");
  EXPECT_EQ(cases.back().name, "S3_300kPa");
  for (const StudyCase& c : cases) EXPECT_EQ(c.job, "triaxial") << c.config;
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

TEST(Study, SummaryRoundTripsInFileUnits) {
  const auto dir = std::filesystem::path(::testing::TempDir()) / ("triaxdem_study_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
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
  std::ofstream(dir / "broken.csv") << "kind,balls\nmembrane,3\n";
  try {
    read_summary((dir / "broken.csv").string());
    FAIL() << "columns are missing";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("wall_s"), std::string::npos) << e.what();
  }
}
