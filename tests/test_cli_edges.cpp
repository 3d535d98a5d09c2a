// Settings that would make a result meaningless or lose a file are refused before any run (issue 40): the
// program itself, run as a user runs it, on the shipped configs.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "host/progress.hpp"
#include "test_util.hpp"

namespace fs = std::filesystem;

namespace {

struct Outcome {
  int code = -1;
  std::string output;
};

/// `triaxdem ARGS`, its exit code and what it printed (stdout and stderr).
Outcome triaxdem(const std::string& args, const fs::path& dir) {
  const fs::path log = dir / "log.txt";
  const std::string cmd = "cd " + std::string(TRIAXDEM_SOURCE_DIR) + " && OMP_NUM_THREADS=1 " TRIAXDEM_BINARY " " +
                          args + " > " + log.string() + " 2>&1";
  const int status = std::system(cmd.c_str());
  std::ifstream in(log);
  Outcome o;
  o.output.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  o.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return o;
}

}  // namespace

// `--free mu_s,mu_s` was taken as two parameters (a singular fit): refused with the option, and no result folder
// is left behind.
TEST(CliEdges, ARepeatedFreeParameterIsRefused) {
  const fs::path dir = dem::test::scratch_dir("cli_free");
  const Outcome o = triaxdem("calibrate data/tang2025_table6_peak.csv --config configs/calibration/base.toml "
                             "--free mu_s,mu_s --predict none -o " + (dir / "out").string(), dir);
  EXPECT_EQ(o.code, 1) << o.output;
  EXPECT_NE(o.output.find("--free: mu_s given twice"), std::string::npos) << o.output;
  EXPECT_FALSE(fs::exists(dir / "out")) << "a refused calibration left a folder";
}

// `synth -o` replaced any file, its own config included; a strength outside the parameter's range was accepted
// (wear 5) or silently replaced by a drawn one (-1).
TEST(CliEdges, SynthNeverWritesOverItsConfigNorOutOfRange) {
  const fs::path dir = dem::test::scratch_dir("cli_synth");
  const fs::path config = dir / "base.toml";
  fs::copy_file(fs::path(TRIAXDEM_SOURCE_DIR) / "configs/calibration/base.toml", config);
  const std::string before = [&] {
    std::ifstream in(config);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }();
  Outcome o = triaxdem("synth --config " + config.string() + " -o " + config.string() + " --overwrite", dir);
  EXPECT_EQ(o.code, 1);
  EXPECT_NE(o.output.find("that is the config"), std::string::npos) << o.output;
  std::ifstream in(config);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()), before);
  const fs::path other = dir / "data.csv";
  std::ofstream(other) << "keep me\n";
  o = triaxdem("synth --config " + config.string() + " -o " + other.string(), dir);
  EXPECT_EQ(o.code, 1);
  EXPECT_NE(o.output.find("the file exists (--overwrite replaces it)"), std::string::npos) << o.output;
  for (const char* strength : {"5", "-1"}) {
    o = triaxdem("synth --config " + config.string() + " -o " + (dir / "new.csv").string() +
                     " --extension wear --strength " + strength, dir);
    EXPECT_EQ(o.code, 1) << strength;
    EXPECT_NE(o.output.find("out of the range of wear (allowed: [0, 0.9])"), std::string::npos) << o.output;
    EXPECT_FALSE(fs::exists(dir / "new.csv"));
  }
}

// A calibration that widens its search ran past its planned runs and printed "840/840 (100%) ETA 0m00s" for many
// silent minutes: past the plan the line says so, and keeps coming (a log gets one per tenth, or every 30 s).
TEST(CliEdges, ProgressPastItsPlanSaysSo) {
  testing::internal::CaptureStdout();
  dem::Progress p("calibrate S-1", 10);
  p.update(5);
  p.update(12, "runs");
  const std::string out = testing::internal::GetCapturedStdout();
  EXPECT_NE(out.find("calibrate S-1 12, beyond the 10 planned; elapsed"), std::string::npos) << out;
  EXPECT_EQ(out.find("12/10"), std::string::npos) << out;
}

// `triaxdem check /dev/zero` read without end (9.7 GB after 16 s): a device is refused by name, and so is a
// config over the size cap, with the cap, before it is held in memory.
TEST(CliEdges, ADeviceOrAHugeFileIsNoConfig) {
  const fs::path dir = dem::test::scratch_dir("cli_big");
  Outcome o = triaxdem("check /dev/zero", dir);
  EXPECT_EQ(o.code, 1);
  EXPECT_NE(o.output.find("/dev/zero: not a regular file"), std::string::npos) << o.output;
  const fs::path big = dir / "big.toml";
  {
    std::ofstream f(big);
    f << "# " << std::string(2 << 20, 'x') << "\n";
  }
  o = triaxdem("check " + big.string(), dir);
  EXPECT_EQ(o.code, 1);
  EXPECT_NE(o.output.find("larger than 1024 KiB"), std::string::npos) << o.output;
}
