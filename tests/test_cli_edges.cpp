// Settings that would make a result meaningless or lose a file are refused before any run: the
// program itself, run as a user runs it, on the shipped configs.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "host/data/compression_data.hpp"
#include "host/engine/checkpoint.hpp"
#include "host/util/folder_lock.hpp"
#include "host/util/progress.hpp"
#include "host/engine/simulation.hpp"
#include "test_util.hpp"

namespace fs = std::filesystem;

namespace {

struct Outcome {
  int code = -1;
  std::string output;
};

/// `triaxdem ARGS` (after `prefix`: the environment, or a command that runs it), its exit code and what it
/// printed (stdout and stderr). A child still running after 5 minutes is stopped (exit code 124): the longest of
/// these tests takes about 20 s, and a job that should have been refused and runs instead (for hours) fails its
/// test with what it printed. ctest's TIMEOUT ends the test's process only; the job would run on beside the next
/// tests. The line runs in `sh -c '...'`, its own single quotes escaped, so a prefix may hold shell syntax.
Outcome triaxdem(const std::string& args, const fs::path& dir, const std::string& prefix = "OMP_NUM_THREADS=1") {
  const fs::path log = dir / "log.txt";
  std::string line = prefix + " " + dem::test::triaxdem_binary() + " " + args;
  for (std::size_t at = 0; (at = line.find('\'', at)) != std::string::npos; at += 4) line.replace(at, 1, "'\\''");
  const std::string cmd = "cd " + std::string(TRIAXDEM_SOURCE_DIR) + " && timeout -k 10 300 sh -c '" + line + "' > " +
                          log.string() + " 2>&1";
  const int status = std::system(cmd.c_str());
  std::ifstream in(log);
  Outcome o;
  o.output.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  o.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return o;
}

std::string text_of(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// The numeric cells of a CSV file's last row, by column name.
std::map<std::string, double> last_row(const fs::path& file) {
  std::ifstream in(file);
  std::string header, line, last;
  std::getline(in, header);
  while (std::getline(in, line)) last = line;
  std::stringstream h(header), v(last);
  std::map<std::string, double> row;
  for (std::string name, cell; std::getline(h, name, ',') && std::getline(v, cell, ',');) {
    char* end = nullptr;
    const double x = std::strtod(cell.c_str(), &end);
    if (end != cell.c_str() && *end == '\0') row[name] = x;
  }
  return row;
}

/// tests/data/tiny_triaxial.toml (450 beads: seconds) with `specimen_extra` added to its last table, [specimen].
fs::path tiny_triaxial_file(const fs::path& dir, const std::string& specimen_extra) {
  const fs::path file = dir / "tiny.toml";
  std::ofstream(file) << text_of(fs::path(TRIAXDEM_SOURCE_DIR) / "tests/data/tiny_triaxial.toml") << specimen_extra;
  return file;
}

/// One test of four points, material A at 100 kPa: data that a calibration reads before it refuses something else.
void write_four_point_curve(const fs::path& path) {
  std::ofstream(path) << "material,sigma3_kPa,eps_a_pct,q_kPa,eps_v_pct\n"
                         "A,100,0,0,0\nA,100,1,60,0.1\nA,100,2,70,-0.1\nA,100,3,65,-0.3\n";
}

/// The shipped file `source` (from the source root) with its first `from` replaced by `to`, written to `out`.
void write_edited(const std::string& source, const std::string& from, const std::string& to, const fs::path& out) {
  std::string text = text_of(fs::path(TRIAXDEM_SOURCE_DIR) / source);
  const std::string::size_type at = text.find(from);
  if (at == std::string::npos) {
    ADD_FAILURE() << source << " holds no '" << from << "'";
    return;
  }
  std::ofstream(out) << text.replace(at, from.size(), to);
}

}  // namespace

// A full disk while writing HDF5 printed some 640 lines of HDF5's error stack and then crashed at exit (signal 11 in
// H5F__close_cb, exit 139; issue 65): one clear error, exit 1, and the files written before it kept. A file size
// limit stands in for the full disk (writes fail with EFBIG as with ENOSPC; SIGXFSZ ignored, as a full disk sends none).
TEST(CliEdges, AFullDiskStopsTheRunWithOneClearError) {
  const fs::path dir = dem::test::scratch_dir("cli_full_disk");
  // ulimit -f counts 512-byte blocks in sh: 300 kB, above a snapshot of this run (190 kB), below its checkpoint.
  const Outcome o = triaxdem("run configs/default.toml -n 2000 -o " + (dir / "r").string(), dir,
                             "trap '' XFSZ; ulimit -f 600; OMP_NUM_THREADS=1");
  EXPECT_EQ(o.code, 1) << o.output;
  EXPECT_NE(o.output.find("triaxdem: error: cannot write '" + (dir / "r").string() + "/"), std::string::npos)
      << o.output;
  EXPECT_EQ(o.output.find("HDF5-DIAG"), std::string::npos) << o.output;
  EXPECT_TRUE(fs::exists(dir / "r" / "series.csv")) << "what was written before the disk filled is kept";
}

// Two runs started at once into one folder both went on and left a mixture of their files: a run locks its folder
// before it writes, and a second is refused naming the first; the lock goes with the run.
TEST(CliEdges, ASecondRunIntoARunningRunsFolderIsRefused) {
  const fs::path dir = dem::test::scratch_dir("cli_lock");
  const fs::path out = dir / "out";
  {
    const dem::io::FolderLock held(out.string());
    const Outcome o = triaxdem("run configs/default.toml -n 5 -o " + out.string(), dir);
    EXPECT_EQ(o.code, 1) << o.output;
    EXPECT_NE(o.output.find("is in use by another run (pid " + std::to_string(getpid())), std::string::npos) << o.output;
    EXPECT_FALSE(fs::exists(out / "series.csv")) << "the refused run wrote";
  }
  const Outcome o = triaxdem("run configs/default.toml -n 5 -o " + out.string(), dir);
  EXPECT_EQ(o.code, 0) << o.output;
  EXPECT_TRUE(fs::exists(out / "series.csv"));
  EXPECT_FALSE(fs::exists(out / ".triaxdem.lock")) << "the run left its lock behind";
  // The same for synth's one file: two at once into one file both exited 0, one file replacing the other (issue 65).
  const fs::path file = dir / "same.csv";
  {
    const dem::io::FolderLock held = dem::io::FolderLock::of_file(file.string());
    const Outcome s = triaxdem("synth --config configs/calibration/base.toml -o " + file.string(), dir);
    EXPECT_EQ(s.code, 1) << s.output;
    EXPECT_NE(s.output.find("output file '" + file.string() + "' is in use by another run (pid " +
                            std::to_string(getpid())), std::string::npos) << s.output;
  }
  EXPECT_FALSE(fs::exists(file)) << "the refused synth wrote";
  EXPECT_FALSE(fs::exists(dir / ".same.csv.lock")) << "the lock outlived its holder";
}

// `study -t 100000` and OMP_NUM_THREADS=100000 crashed every case with signal 11 and an empty log: counts beyond
// the machine are refused, naming the option or variable and the allowed range.
TEST(CliEdges, ThreadAndJobCountsBeyondTheMachineAreRefused) {
  const fs::path dir = dem::test::scratch_dir("cli_threads");
  Outcome o = triaxdem("study configs/small -t 100000 -o " + (dir / "s").string(), dir);
  EXPECT_NE(o.code, 0) << o.output;
  EXPECT_NE(o.output.find("--threads: 100000 is no count for this machine (allowed: 0 for the default, 1 to "),
            std::string::npos) << o.output;
  o = triaxdem("calibrate data/tang2025_table6_peak.csv --config configs/calibration/base.toml -j 0", dir);
  EXPECT_NE(o.output.find("--jobs: 0 is no count for this machine (allowed: 1 to "), std::string::npos) << o.output;
  o = triaxdem("info", dir, "OMP_NUM_THREADS=100000");
  EXPECT_EQ(o.code, 1) << o.output;
  EXPECT_NE(o.output.find("OMP_NUM_THREADS=100000 is no thread count for this machine (allowed: 1 to "),
            std::string::npos) << o.output;
  EXPECT_EQ(triaxdem("info", dir, "OMP_NUM_THREADS=1").code, 0);
}

// The main job (the README's first command) ran for minutes with progress but never said before it began what it
// would run and about how long: it prints its plan, the balls, steps and time of its consolidation and shear on this
// machine, before the specimen's layers (here refused at their step cap, so the test takes a second).
TEST(CliEdges, TheTriaxialJobTellsItsCostBeforeTheWork) {
  const fs::path dir = dem::test::scratch_dir("cli_triaxial_plan");
  const Outcome o = triaxdem("triaxial " + tiny_triaxial_file(dir, "max_steps_per_layer = 300\n").string() + " -o " +
                             (dir / "run").string(), dir);
  const std::size_t plan = o.output.find("triaxial: plan: "), layers = o.output.find("specimen layer");
  ASSERT_NE(plan, std::string::npos) << o.output;
  EXPECT_LT(plan, layers) << o.output;
  const std::string line = o.output.substr(plan, o.output.find('\n', plan) - plan);
  long balls = 0;
  double steps = 0;
  ASSERT_EQ(std::sscanf(line.c_str(), "triaxial: plan: %ld balls, consolidation to %*f kPa and shear to %*f%% axial "
                                      "strain: %lf steps", &balls, &steps), 2) << line;
  EXPECT_GT(balls, 0) << line;
  EXPECT_GT(steps, 0) << line;
  EXPECT_NE(line.find(" on this machine"), std::string::npos) << line;
}

// The periodic job too says what it will run and about how long before the work: its packing at its preparation
// friction's cost (a range: packing_cost_at), its consolidation and shear.
TEST(CliEdges, ThePeriodicJobTellsItsCostBeforeTheWork) {
  const fs::path dir = dem::test::scratch_dir("cli_periodic_plan");
  write_edited("tests/data/hidden_effects.toml", "target_axial_strain_pct = 8.0", "target_axial_strain_pct = 0.4",
               dir / "cell.toml");
  const Outcome o = triaxdem("periodic " + (dir / "cell.toml").string() + " -o " + (dir / "run").string(), dir);
  EXPECT_EQ(o.code, 0) << o.output;
  const std::size_t plan = o.output.find("periodic: plan: "), packing = o.output.find("triaxdem: preparation");
  ASSERT_NE(plan, std::string::npos) << o.output;
  EXPECT_LT(plan, packing) << o.output;
  const std::string line = o.output.substr(plan, o.output.find('\n', plan) - plan);
  long balls = 0;
  double low = 0, high = 0;
  ASSERT_EQ(std::sscanf(line.c_str(),
                        "periodic: plan: %ld balls, a packing (preparation friction %*f: %lf to %lf steps)", &balls,
                        &low, &high),
            3) << line;
  EXPECT_EQ(balls, 120) << line;
  EXPECT_GT(low, 0) << line;
  EXPECT_GT(high, low) << line;
  EXPECT_NE(line.find(" on this machine"), std::string::npos) << line;
}

// The compression command (issue 88): the cell's oedometer says what it will run before the packing, writes a row per
// increment (the seating state first) with K0 = sigma_h / sigma_v, and refuses a test it does not know, naming the
// ones it does.
TEST(CliEdges, TheCompressionJobWritesARowPerIncrement) {
  const fs::path dir = dem::test::scratch_dir("cli_compression");
  const std::string cell = (dir / "cell.toml").string();
  write_edited("tests/data/hidden_effects.toml", "target_axial_strain_pct = 8.0", "target_axial_strain_pct = 8.0",
               cell);
  const Outcome o = triaxdem("compression " + cell + " --stresses 200,400 -o " + (dir / "run").string(), dir);
  EXPECT_EQ(o.code, 0) << o.output;
  const std::size_t plan = o.output.find("compression: plan: 120 balls"), packing = o.output.find("preparation");
  ASSERT_NE(plan, std::string::npos) << o.output;
  EXPECT_LT(plan, packing) << o.output;
  std::ifstream series(dir / "run" / "series.csv");
  std::string header, line;
  std::getline(series, header);
  EXPECT_NE(header.find("K0"), std::string::npos) << header;
  int rows = 0;
  while (std::getline(series, line)) ++rows;
  EXPECT_EQ(rows, 3) << "the seating state and two increments";
  // The record as compression data, which calibrate --compression reads: the increments from the seating state.
  const std::vector<dem::CompressionTest> data = dem::load_compression((dir / "run" / "compression_data.csv").string());
  ASSERT_EQ(data.size(), 1u);
  EXPECT_EQ(data[0].material, "hidden-effect tests");
  ASSERT_EQ(data[0].stress.size(), 2u);
  EXPECT_DOUBLE_EQ(data[0].stress[1], 400e3);
  EXPECT_GT(data[0].strain[1], data[0].strain[0]);
  EXPECT_GT(data[0].strain[0], 0);
  // Compression data of a material the triaxial data lack are refused before any work, naming both files.
  const Outcome lone = triaxdem("calibrate " + std::string(TRIAXDEM_SOURCE_DIR) + "/data/tang2025_table6_peak.csv "
                                "--config " + cell + " --compression " + (dir / "run" / "compression_data.csv").string() +
                                " --plan -o " + (dir / "cal").string(), dir);
  EXPECT_NE(lone.code, 0);
  EXPECT_NE(lone.output.find("compression_data.csv:material: 'hidden-effect tests' has no triaxial tests in"),
            std::string::npos) << lone.output;
  const Outcome bad = triaxdem("compression " + cell + " --test triaxial -o " + (dir / "bad").string(), dir);
  EXPECT_NE(bad.code, 0);
  EXPECT_NE(bad.output.find("oedometer"), std::string::npos) << bad.output;
  // diagnose takes them beside the material's triaxial tests (here three peaks), and its plan prices them.
  std::ofstream(dir / "peaks.csv") << "material,sigma3_kPa,q_peak_kPa\nhidden-effect tests,100,150\n"
                                      "hidden-effect tests,200,290\nhidden-effect tests,300,420\n";
  const Outcome diagnosis = triaxdem("diagnose " + (dir / "peaks.csv").string() + " --config " + cell +
                                     " --free emod_Pa,mu_s --predict none --compression " +
                                     (dir / "run" / "compression_data.csv").string() + " --plan -o " +
                                     (dir / "diagnose").string(), dir);
  EXPECT_EQ(diagnosis.code, 0) << diagnosis.output;
  EXPECT_NE(diagnosis.output.find("hidden-effect tests: compression tests"), std::string::npos) << diagnosis.output;
  // One specimen a point cannot fit them (it whitens a run of one specimen): calibrate refuses the config's method
  // with them, naming it; a diagnosis searches with the ensemble whatever the method says, and takes them.
  const std::string one = (dir / "one_specimen.toml").string();
  write_edited("tests/data/hidden_effects.toml", "free = [\"mu_s\", \"mu_r\"]",
               "free = [\"mu_s\", \"mu_r\"]\nmethod = \"one_specimen\"", one);
  const std::string with = " --free emod_Pa,mu_s --predict none --compression " +
                           (dir / "run" / "compression_data.csv").string() + " --plan -o " + (dir / "one").string();
  const Outcome refused = triaxdem("calibrate " + (dir / "peaks.csv").string() + " --config " + one + with, dir);
  EXPECT_NE(refused.code, 0);
  EXPECT_NE(refused.output.find("[calibrate] method: \"one_specimen\" with --compression"), std::string::npos)
      << refused.output;
  const Outcome taken = triaxdem("diagnose " + (dir / "peaks.csv").string() + " --config " + one + with, dir);
  EXPECT_EQ(taken.code, 0) << taken.output;
}

// A cell test that blows up stops with the jobs' status for it, 2, its state saved beside the series for
// inspection, in its shear (inertial number 1, far past what the contacts' stiffness holds at 300 kPa) and in its
// preparation (an overlap limit of 1% of the radius, which a packing at 100 kPa of these balls passes). The shear's
// saving read the blown-up step's statistics again and threw a second time (status 1, no checkpoint); the
// preparation's ran outside the job's blow-up handling (status 1, nothing saved).
TEST(CliEdges, ACellsBlowUpSavesItsState) {
  const fs::path dir = dem::test::scratch_dir("cli_cell_blowup");
  const std::vector<std::pair<std::string, std::string>> shear = {{"sigma3_kPa = 100.0", "sigma3_kPa = 300.0"},
                                                                  {"target_inertial = 3e-3", "target_inertial = 1.0"}},
                                                         preparation = {{"dt_safety = 0.2",
                                                                         "dt_safety = 0.2\noverlap_limit = 0.01"}};
  for (const auto& [name, edits] : {std::pair{std::string("shear"), shear}, {"preparation", preparation}}) {
    std::string text = text_of(fs::path(TRIAXDEM_SOURCE_DIR) / "tests/data/hidden_effects.toml");
    for (const auto& [from, to] : edits) {
      ASSERT_NE(text.find(from), std::string::npos) << from;
      text.replace(text.find(from), from.size(), to);
    }
    const fs::path config = dir / (name + ".toml"), run = dir / name;
    std::ofstream(config) << text;
    const Outcome o = triaxdem("periodic " + config.string() + " -o " + run.string(), dir);
    EXPECT_EQ(o.code, 2) << name << "\n" << o.output;
    EXPECT_NE(o.output.find("blow-up at step"), std::string::npos) << name << "\n" << o.output;
    EXPECT_NE(o.output.find("state at the blow-up saved in"), std::string::npos) << name << "\n" << o.output;
    const std::string saved = dem::blowup_path(run.string());
    ASSERT_TRUE(fs::exists(saved)) << name << "\n" << o.output;
    const dem::Checkpoint c = dem::read_checkpoint(saved);
    EXPECT_EQ(c.job, "periodic") << name;
    EXPECT_GT(c.sim.step, 0) << name;
  }
}

// A membrane specimen's layer that blows up (an overlap limit of 3% of the radius, which the compaction of these
// beads passes) stops the specimen and triaxial commands with status 2, the layer's state saved for inspection, where
// the blow-up was said and nothing saved.
TEST(CliEdges, ASpecimenLayersBlowUpSavesItsState) {
  const fs::path dir = dem::test::scratch_dir("cli_layer_blowup");
  write_edited("tests/data/tiny_triaxial.toml", "overlap_limit = 0.25", "overlap_limit = 0.03", dir / "tiny.toml");
  for (const std::string job : {"specimen", "triaxial"}) {
    const fs::path run = dir / job;
    const Outcome o = triaxdem(job + " " + (dir / "tiny.toml").string() + " -o " + run.string(), dir);
    EXPECT_EQ(o.code, 2) << job << "\n" << o.output;
    EXPECT_NE(o.output.find("blow-up at step"), std::string::npos) << job << "\n" << o.output;
    EXPECT_NE(o.output.find("the specimen layer's state at the blow-up saved in"), std::string::npos)
        << job << "\n" << o.output;
    const std::string saved = dem::blowup_path(run.string());
    ASSERT_TRUE(fs::exists(saved)) << job << "\n" << o.output;
    EXPECT_EQ(dem::read_checkpoint(saved).job, "specimen") << job;
  }
}

// A specimen whose layer the step cap stopped before it came to rest warned and went on (exit 0): it is refused,
// naming the keys, unless accepted; the refused specimen is kept, so the rerun that accepts it does not build it
// again; and a resume reads the run's own copy, so clearing the shared cache costs nothing.
TEST(CliEdges, AnUnsettledSpecimenIsRefusedUnlessAcceptedAndKeptForTheRerun) {
  const fs::path dir = dem::test::scratch_dir("cli_unsettled");
  const std::string out = " -o " + (dir / "run").string();
  Outcome o = triaxdem("triaxial " + tiny_triaxial_file(dir, "max_steps_per_layer = 300\n").string() + out, dir);
  EXPECT_EQ(o.code, 1) << o.output;
  EXPECT_NE(o.output.find("[specimen] layer 1/3 stopped at max_steps_per_layer = 300 with the unbalanced ratio at"),
            std::string::npos) << o.output;
  EXPECT_NE(o.output.find("set accept_unsettled = true"), std::string::npos) << o.output;
  // `specimen` blamed the void ratio first ("not reachable ... try a larger e"), which the step cap explains
  // (issue 65): the cap's error alone.
  o = triaxdem("specimen " + tiny_triaxial_file(dir, "max_steps_per_layer = 300\n").string() + " -o " +
               (dir / "specimen").string(), dir);
  EXPECT_EQ(o.code, 1) << o.output;
  EXPECT_NE(o.output.find("stopped at max_steps_per_layer = 300"), std::string::npos) << o.output;
  EXPECT_EQ(o.output.find("not reachable"), std::string::npos) << o.output;
  const std::string accepted =
      tiny_triaxial_file(dir, "max_steps_per_layer = 300\naccept_unsettled = true\n").string();
  o = triaxdem("triaxial " + accepted + out + " --overwrite --stop-at-step 2", dir);
  EXPECT_EQ(o.code, 3) << o.output;
  EXPECT_EQ(o.output.find("specimen layer"), std::string::npos) << "built again:\n" << o.output;
  fs::remove_all(dir / ".specimens");
  o = triaxdem("triaxial " + accepted + out + " --resume --stop-at-step 4", dir);
  EXPECT_EQ(o.code, 3) << o.output;
  EXPECT_NE(o.output.find("specimen: the run's own"), std::string::npos) << o.output;
  EXPECT_EQ(o.output.find("specimen layer"), std::string::npos) << "built again on resume:\n" << o.output;
  // Step 0 comes before any step and was ignored (the test ran to its end, issue 65): refused, naming the option.
  // Issue 87: 0 was refused as "not in range 0.000000 to 1.8e308", 1.5 as "Could not convert".
  for (const char* step : {"0", "-1", "1.5"}) {
    o = triaxdem("triaxial " + accepted + out + " --overwrite --stop-at-step " + step, dir);
    EXPECT_NE(o.code, 0) << o.output;
    EXPECT_NE(o.output.find("--stop-at-step"), std::string::npos) << o.output;
    EXPECT_NE(o.output.find(std::string(step) + " is no step (a whole number, 1 or more"), std::string::npos) << o.output;
  }
}

// A SIGTERM (or Ctrl-C) while the specimen was being built was held until the whole build had ended (minutes to
// an hour at full scale): it now stops the build, saying that nothing was stored.
TEST(CliEdges, AStopSignalEndsTheSpecimenBuild) {
  const fs::path dir = dem::test::scratch_dir("cli_term");
  const auto start = std::chrono::steady_clock::now();
  // The shipped small specimen takes about two minutes on one thread: the signal comes in its first layer.
  const Outcome o = triaxdem("triaxial configs/small/S1_100kPa.toml -o " + (dir / "run").string(), dir,
                             "OMP_NUM_THREADS=1 timeout --preserve-status -s TERM 2");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(o.code, 128 + SIGTERM) << o.output;
  EXPECT_NE(o.output.find("SIGTERM during the specimen build: nothing was stored"), std::string::npos) << o.output;
  EXPECT_LT(seconds, 30) << "the build went on after the signal";
  EXPECT_FALSE(fs::exists(dir / ".specimens")) << "a half-built specimen was stored";
}

// A data void ratio of 4.5 was matched by the loosest packing the cell reaches (0.87) and calibrated on: a state
// beyond the preparation's reach by more than kMaxStateGap is refused, with both ends of that reach.
TEST(CliEdges, ADataStateBeyondTheCellsReachIsRefused) {
  const fs::path dir = dem::test::scratch_dir("cli_state");
  std::ofstream(dir / "loose.csv") << "material,sigma3_kPa,eps_a_pct,q_kPa,eps_v_pct,void_ratio\n"
                                      "A,100,0,0,0,4.5\nA,100,1,60,0.1,4.5\nA,100,2,70,-0.1,4.5\nA,100,3,65,-0.3,4.5\n";
  const Outcome o = triaxdem("calibrate " + (dir / "loose.csv").string() + " --config tests/data/hidden_effects.toml "
                             "--predict none -j 1 -o " + (dir / "out").string(), dir);
  EXPECT_EQ(o.code, 1) << o.output;
  EXPECT_NE(o.output.find("the data's void ratio 4.5000 is beyond this cell's reach: preparation friction 0 to 1 "
                          "packs it at 0."), std::string::npos) << o.output;
}

// The README writes `triaxdem ...` and nothing said which build a result came from: --version names the version,
// the commit and the Kokkos backend, and every summary.csv carries them with the config's path, hash and seed.
TEST(CliEdges, VersionAndProvenance) {
  const fs::path dir = dem::test::scratch_dir("cli_version");
  Outcome o = triaxdem("--version", dir);
  EXPECT_EQ(o.code, 0) << o.output;
  EXPECT_EQ(o.output.rfind("triaxdem " TRIAXDEM_VERSION "+", 0), 0u) << o.output;
  EXPECT_NE(o.output.find("(Kokkos "), std::string::npos) << o.output;
  o = triaxdem("triaxial tests/data/tiny_triaxial.toml -o " + (dir / "run").string(), dir);
  ASSERT_EQ(o.code, 0) << o.output;
  const std::string summary = text_of(dir / "run" / "summary.csv");
  EXPECT_NE(summary.find(",version,backend,config,config_hash,seed\n"), std::string::npos) << summary;
  EXPECT_NE(summary.find("," TRIAXDEM_VERSION "+"), std::string::npos) << summary;
  EXPECT_NE(summary.find(",tests/data/tiny_triaxial.toml,"), std::string::npos) << summary;
  // The membrane series has p, the void ratio and the mobilised friction angle, as the periodic one has; e from
  // eps_v and the consolidated e0 of summary.csv (6 digits there).
  const auto row = last_row(dir / "run" / "series.csv");
  for (const char* name : {"q_kPa", "sigma3_kPa", "eps_v_pct", "p_kPa", "void_ratio", "phi_mob_deg"})
    ASSERT_TRUE(row.count(name)) << name << " missing from series.csv";
  const double q = row.at("q_kPa"), s3 = row.at("sigma3_kPa");
  EXPECT_NEAR(row.at("p_kPa"), s3 + q / 3, 1e-6 * s3);
  EXPECT_NEAR(std::sin(row.at("phi_mob_deg") * M_PI / 180), q / (q + 2 * s3), 1e-6);
  const double e0 = last_row(dir / "run" / "summary.csv").at("void_ratio0");
  EXPECT_NEAR(row.at("void_ratio"), (1 + e0) * (1 - row.at("eps_v_pct") / 100) - 1, 1e-5);
}

// `check` on a triaxial config reported "2000 balls, 6 walls", the run job's default box: it describes the job the
// config is for, with its ball count, stages, time step, steps and a wall-time estimate.
TEST(CliEdges, CheckDescribesTheJobTheConfigIsFor) {
  const fs::path dir = dem::test::scratch_dir("cli_check");
  Outcome o = triaxdem("check tests/data/tiny_triaxial.toml", dir);
  EXPECT_EQ(o.code, 0) << o.output;
  for (const char* part : {"a drained triaxial test (triaxdem triaxial)", "specimen: 452 beads of 2 mm in a 16 x 16 mm",
                           "membrane: 24 x 8 nodes", "shear: inertial number 1.0e-02", "(150 records)", "time step: ",
                           "estimate: the shear about "})
    EXPECT_NE(o.output.find(part), std::string::npos) << part << " missing:\n" << o.output;
  EXPECT_EQ(o.output.find("2000 balls"), std::string::npos) << o.output;
  o = triaxdem("check configs/periodic/periodic_S1_100kPa.toml", dir);
  EXPECT_NE(o.output.find("a periodic-cell triaxial test (triaxdem periodic):\n  cell: 1000 balls"), std::string::npos)
      << o.output;
  // What `periodic` refuses, `check` refuses with the same words (it said OK to gravity in the cell, issue 65).
  write_edited("configs/periodic/periodic_S1_100kPa.toml", "gravity = [0.0, 0.0, 0.0]", "gravity = [0.0, 0.0, -9.81]",
               dir / "gravity.toml");
  for (const char* job : {"check", "periodic"}) {
    o = triaxdem(std::string(job) + " " + (dir / "gravity.toml").string() +
                     (std::string(job) == "check" ? "" : " -o " + (dir / "g").string()), dir);
    EXPECT_NE(o.code, 0) << job << "\n" << o.output;
    EXPECT_NE(o.output.find("gravity.toml: [solver] gravity: must be [0, 0, 0] in the cell test"), std::string::npos)
        << job << "\n" << o.output;
  }
  // A box without walls under gravity: check said OK, and run stopped at the first ball out with a blow-up that
  // blamed a wall (issue 65). Both refuse it before any step.
  write_edited("configs/default.toml", "walls = true", "walls = false", dir / "open.toml");
  for (const char* job : {"check", "run"}) {
    o = triaxdem(std::string(job) + " " + (dir / "open.toml").string() +
                     (std::string(job) == "check" ? "" : " -n 10 -o " + (dir / "open").string()), dir);
    EXPECT_NE(o.code, 0) << job << "\n" << o.output;
    EXPECT_NE(o.output.find("open.toml: [box] walls = false with [solver] gravity along z: nothing holds the balls"),
              std::string::npos) << job << "\n" << o.output;
    EXPECT_EQ(o.output.find("blow-up"), std::string::npos) << job << "\n" << o.output;
  }
}

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
    // The key's own range (issue 87: the search's [0, 0.9] was said where docs/config.md gives [0, 0.99]).
    EXPECT_NE(o.output.find("out of the range of wear (allowed: [0, 0.99], as [material] wear takes it)"),
              std::string::npos) << o.output;
    EXPECT_FALSE(fs::exists(dir / "new.csv"));
  }
  // Taken silently before (issue 65): a NaN strength (replaced by a drawn one), a strength with no extension (dropped),
  // one pressure given twice (merged into one test that calibrate refused). Each refused before any run.
  const std::string synth = "synth --config " + config.string() + " -o " + (dir / "new.csv").string();
  const std::pair<std::string, std::string> refused[] = {
      {" --extension wear --strength nan", "--strength: nan is not a number"},
      {" --extension none --strength 0.3", "synth --strength 0.3: --extension none has no strength"},
      {" --pressures 100 100", "synth --pressures: 100 and 100 kPa are one pressure"}};
  for (const auto& [args, said] : refused) {
    o = triaxdem(synth + args, dir);
    EXPECT_NE(o.code, 0) << args;
    EXPECT_NE(o.output.find(said), std::string::npos) << args << "\n" << o.output;
    EXPECT_EQ(o.output.find("a specimen each (packed first)"), std::string::npos)
        << "work started: " << args << "\n" << o.output;
    EXPECT_FALSE(fs::exists(dir / "new.csv")) << args;
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

// A specimen layer printed "12000/12000 (100%) ETA 0m00s" for 20-30 s while it settled (the platen at its height,
// the unbalanced ratio going up and down): a settling stage gives no ETA, says what it waits for, and its first
// line comes at once.
TEST(CliEdges, ASettlingStageGivesNoETA) {
  testing::internal::CaptureStdout();
  dem::Progress p("specimen layer 3/5", 12000);
  p.update(12000, "(um of platen travel)");
  p.settling("settling until the unbalanced ratio is below 1e-03 (now 4.5e-03)");
  p.settling("not due yet: a log gets one line a tenth or every 30 s");
  const std::string out = testing::internal::GetCapturedStdout();
  EXPECT_NE(out.find("specimen layer 3/5 12000/12000 (100%) elapsed 0m00s, no ETA: settling until the unbalanced "
                     "ratio is below 1e-03 (now 4.5e-03)"), std::string::npos) << out;
  EXPECT_EQ(out.find("not due yet"), std::string::npos) << out;
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

// `triaxdem bogus` said only "A subcommand is required": the word is named, with the commands there are.
TEST(CliEdges, AnUnknownCommandIsNamedWithTheCommandsThereAre) {
  const fs::path dir = dem::test::scratch_dir("cli_bogus");
  const Outcome o = triaxdem("bogus", dir);
  EXPECT_EQ(o.code, 1);
  EXPECT_NE(o.output.find("'bogus' is no triaxdem command; the commands: run, "), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("calibrate"), std::string::npos) << o.output;
}

// `synth --pressures 0` failed after 6 s naming sigma3, a key the user never typed: the option is refused at once.
TEST(CliEdges, AZeroPressureIsRefusedNamingTheOption) {
  const fs::path dir = dem::test::scratch_dir("cli_pressures");
  const Outcome o = triaxdem("synth --config configs/calibration/base.toml --pressures 100 0 -o " +
                             (dir / "s.csv").string(), dir);
  EXPECT_EQ(o.code, 105) << o.output;  // CLI11's validation failure
  EXPECT_NE(o.output.find("--pressures"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("0 is no confining pressure (kPa, a number above 0)"), std::string::npos) << o.output;
  EXPECT_FALSE(fs::exists(dir / "s.csv"));
}

// `--resume -n 1000` on a run already past step 1000 did nothing and said nothing.
TEST(CliEdges, AResumeBehindItsCheckpointSaysSo) {
  const fs::path dir = dem::test::scratch_dir("cli_resume_behind");
  const std::string run = "run configs/default.toml -o " + (dir / "out").string();
  Outcome o = triaxdem(run + " -n 40", dir);
  ASSERT_EQ(o.code, 0) << o.output;
  o = triaxdem(run + " -n 20 --resume", dir);
  EXPECT_EQ(o.code, 1) << o.output;
  EXPECT_NE(o.output.find("is at step 40, the step count is 20 ([run] steps or -n): nothing to continue; give -n "
                          "above 40"), std::string::npos) << o.output;
}

// `micro` on a folder that is not a run said "saved states at: none".
TEST(CliEdges, MicroOnAFolderThatIsNoRunSaysSo) {
  const fs::path dir = dem::test::scratch_dir("cli_micro");
  const Outcome o = triaxdem("micro " + dir.string(), dir);
  EXPECT_EQ(o.code, 1) << o.output;
  EXPECT_NE(o.output.find("not a triaxial run's folder (no snap_*.h5 in it)"), std::string::npos) << o.output;
  // --rve -3 reached the cube's check as "a cube of edge -3 mm" (issue 65): the option is refused as typed.
  const Outcome r = triaxdem("micro " + dir.string() + " --rve -3", dir);
  EXPECT_NE(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("--rve"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("a cube of edge"), std::string::npos) << r.output;
}

// SIGTERM to calibrate ended it with exit 143 and no word, and its children ran on for 1-10 s (issue 65): it says
// what stopped it and stops its children with it. `timeout` sends the signal part way into the calibration.
TEST(CliEdges, SigtermSaysWhatItStoppedAndStopsTheChildren) {
  const fs::path dir = dem::test::scratch_dir("cli_sigterm");
  write_four_point_curve(dir / "d.csv");
  const std::string out = (dir / "out").string();
  const Outcome o = triaxdem("calibrate " + (dir / "d.csv").string() + " --config tests/data/hidden_effects.toml "
                             "--predict none -j 2 -o " + out, dir, "OMP_NUM_THREADS=1 timeout -s TERM 8");
  EXPECT_EQ(o.code, 124) << "not stopped by the signal: " << o.output;
  EXPECT_NE(o.output.find("triaxdem: stopped by SIGTERM"), std::string::npos) << o.output;
  // Every process of this calibration (the children are forks: the same command line) is gone within a second;
  // the pattern's [/] keeps the shell that runs pgrep from matching itself.
  const std::string left = "sleep 1; pgrep -f -- '-o [/]" + out.substr(1) + "' > /dev/null";
  EXPECT_NE(std::system(left.c_str()), 0) << "a child of the stopped calibration runs on";
}

// A calibration refused after it had made its dated result folder left the folder behind, empty.
TEST(CliEdges, ARefusedCalibrationLeavesNoFolder) {
  const fs::path dir = dem::test::scratch_dir("cli_refused_folder");
  write_four_point_curve(dir / "d.csv");
  const Outcome o = triaxdem("calibrate " + (dir / "d.csv").string() + " --config tests/data/hidden_effects.toml "
                             "--predict none --material nosuch -j 1 -o " + (dir / "out").string(), dir);
  EXPECT_EQ(o.code, 1) << o.output;
  EXPECT_NE(o.output.find("no tests of material 'nosuch'"), std::string::npos) << o.output;
  // Refused with the plan's checks, before anything is made: no dated folder, and no parent either.
  EXPECT_FALSE(fs::exists(dir / "out") && !fs::is_empty(dir / "out")) << "a refused calibration left its dated folder";
  EXPECT_EQ(o.output.find("plan (before any packing)"), std::string::npos) << o.output;
}

// A walled calibration at the data's size ran for over an hour, silent for minutes at a time, and nothing said so
// before it began: calibrate and diagnose print their plan (each stage's work, particle-steps and time on this
// machine) before any packing; --plan prints it and stops, making no folder and packing nothing.
TEST(CliEdges, APlanIsPrintedBeforeAnyPackingAndPlanStopsThere) {
  const fs::path dir = dem::test::scratch_dir("cli_plan");
  write_four_point_curve(dir / "d.csv");
  for (const char* kind : {"calibrate", "diagnose"}) {
    const Outcome o = triaxdem(std::string(kind) + " " + (dir / "d.csv").string() + " --config tests/data/hidden_effects.toml "
                               "--predict none -j 1 --plan -o " + (dir / "out").string(), dir);
    EXPECT_EQ(o.code, 0) << o.output;
    for (const std::string& line : {std::string(kind) + ": plan (before any packing):", std::string("scatter runs: "),
                                   std::string("cell's bias check, runs: "), std::string(kind) + ": in all ",
                                   std::string("ns a particle-step")})
      EXPECT_NE(o.output.find(line), std::string::npos) << line << "\n" << o.output;
    EXPECT_EQ(o.output.find("triaxdem: packing"), std::string::npos) << o.output;
    EXPECT_EQ(o.output.find("matching the void ratio"), std::string::npos) << o.output;
    EXPECT_FALSE(fs::exists(dir / "out") && !fs::is_empty(dir / "out")) << "--plan made a result folder";
  }
}

// Refusals after the work: -o naming a file, and a diagnose resumed in a calibrate folder, were refused after the
// packings (12 s and 1 min 38 s). They are refused with the plan's other checks, before any packing or plan.
TEST(CliEdges, AFolderThatCannotBeWrittenIsRefusedBeforeAnyWork) {
  const fs::path dir = dem::test::scratch_dir("cli_plan_folders");
  write_four_point_curve(dir / "d.csv");
  std::ofstream(dir / "a_file") << "x\n";
  fs::create_directories(dir / "calibrate_20260101-000000");
  const std::string job = " " + (dir / "d.csv").string() + " --config tests/data/hidden_effects.toml --predict none -j 1 ";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"calibrate" + job + "-o " + (dir / "a_file").string(), "a_file is a file, not a folder"},
      {"calibrate" + job + "-o " + (dir / "a_file" / "below").string(), "a_file is a file, not a folder"},
      {"diagnose" + job + "--resume " + (dir / "calibrate_20260101-000000").string(),
       "not a diagnose_<date> folder of an earlier diagnose"},
      // Issue 87: /proc passes access() as root, and the folder failed after the plan ("filesystem error"); as root
      // it is "a folder cannot be made there", as another user "/proc cannot be written".
      {"calibrate" + job + "-o /proc/triaxdem_out", "-o /proc/triaxdem_out: "}};
  for (const auto& [args, said] : cases) {
    const Outcome o = triaxdem(args, dir);
    EXPECT_EQ(o.code, 1) << args << "\n" << o.output;
    EXPECT_NE(o.output.find(said), std::string::npos) << args << "\n" << o.output;
    EXPECT_EQ(o.output.find("plan (before any packing)"), std::string::npos) << o.output;
    EXPECT_EQ(o.output.find("triaxdem: packing"), std::string::npos) << o.output;
  }
}

// The walled cell compares the q the data name (fixed_area or area_corrected, both of which its walls measure); data
// that name a q it cannot give (parabolic, a membrane test's bulge correction) are refused with the measures it can,
// before the plan, with the file and the column; the periodic cell takes such data (its two fidelities correct q).
TEST(CliEdges, AQTheWalledCellCannotGiveIsRefusedBeforeAnyWork) {
  const fs::path dir = dem::test::scratch_dir("cli_q_measure");
  std::ofstream(dir / "d.csv") << "material,sigma3_kPa,eps_a_pct,q_kPa,eps_v_pct,q_measure\n"
                                  "A,100,0,0,0,parabolic\nA,100,1,60,0.1,parabolic\nA,100,2,70,-0.1,parabolic\n"
                                  "A,100,3,65,-0.3,parabolic\n";
  const std::string job = "calibrate " + (dir / "d.csv").string() +
                          " --config tests/data/crosscode/walled_base.toml --predict none -j 1 --plan -o " +
                          (dir / "out").string();
  const Outcome walls = triaxdem(job, dir);
  EXPECT_EQ(walls.code, 1) << walls.output;
  for (const std::string& said : {std::string("d.csv:q_measure: 'parabolic' is not a q the cell between walls"),
                                 std::string("fixed_area"), std::string("area_corrected")})
    EXPECT_NE(walls.output.find(said), std::string::npos) << said << "\n" << walls.output;
  EXPECT_EQ(walls.output.find("plan (before any packing)"), std::string::npos) << walls.output;
  const Outcome periodic = triaxdem(job + " --reference-test periodic", dir);
  EXPECT_EQ(periodic.code, 0) << periodic.output;
}

// Between walls the specimen's size is part of the test: data without specimen_balls are taken to be of the walled
// cell's balls, so the plan has no cell's bias check (it extrapolated the walled cell to an infinite specimen, 4 cells
// of 4,000 balls for the 1,000-ball base); given a larger specimen, the check runs toward it.
TEST(CliEdges, AWalledCellTakesItsBallsAsTheDatasSpecimen) {
  const fs::path dir = dem::test::scratch_dir("cli_walled_size");
  std::ofstream(dir / "d.csv") << "material,sigma3_kPa,eps_a_pct,q_kPa,eps_v_pct,q_measure\n"
                                  "A,100,0,0,0,area_corrected\nA,100,1,60,0.1,area_corrected\n"
                                  "A,100,2,70,-0.1,area_corrected\nA,100,3,65,-0.3,area_corrected\n";
  std::ofstream(dir / "big.csv") << "material,sigma3_kPa,eps_a_pct,q_kPa,eps_v_pct,q_measure,specimen_balls\n"
                                    "A,100,0,0,0,area_corrected,4000\nA,100,1,60,0.1,area_corrected,4000\n"
                                    "A,100,2,70,-0.1,area_corrected,4000\nA,100,3,65,-0.3,area_corrected,4000\n";
  for (const char* file : {"d.csv", "big.csv"}) {
    const Outcome o = triaxdem("calibrate " + (dir / file).string() + " --config tests/data/crosscode/walled_base.toml "
                               "--predict none -j 1 --plan -o " + (dir / "out").string(), dir);
    EXPECT_EQ(o.code, 0) << o.output;
    const bool check = o.output.find("cell's bias check, runs: ") != std::string::npos;
    EXPECT_EQ(check, std::string(file) == "big.csv") << file << "\n" << o.output;
    // A walled cell smaller than the data's specimen is said before any work, with what it does to the interior.
    const bool smaller = o.output.find("note: the walled cell of 1000 balls is smaller than the data's specimen of 4000: "
                                       "its walls' looser layer") != std::string::npos;
    EXPECT_EQ(smaller, std::string(file) == "big.csv") << file << "\n" << o.output;
  }
}

// Fewer summary values than free parameters are refused before any work (issue 65: one q_peak for mu_s and mu_r gave
// both values and "chi2 0.0 on 1 data", exit 0); as many as the parameters are a fit with no test of it, accepted
// (a pressure of Table 6 held out leaves two peaks for two frictions).
TEST(CliEdges, FewerDataThanFreeParametersAreRefusedBeforeAnyWork) {
  const fs::path dir = dem::test::scratch_dir("cli_few_data");
  std::ofstream(dir / "one.csv") << "material,sigma3_kPa,q_peak_kPa\nA,100,300\n";
  std::ofstream(dir / "two.csv") << "material,sigma3_kPa,q_peak_kPa\nA,100,300\nA,200,560\n";
  for (const char* file : {"one.csv", "two.csv"}) {
    const Outcome o = triaxdem("calibrate " + (dir / file).string() + " --config configs/calibration/base.toml "
                               "--predict none -j 1 --plan -o " + (dir / "out").string(), dir);
    const bool refused = o.output.find(std::string(file) + ": material A gives 1 summary value for 2 free parameters "
                                       "([calibrate] free): fewer data than parameters") != std::string::npos;
    EXPECT_EQ(refused, std::string(file) == "one.csv") << o.output;
    EXPECT_EQ(o.code == 0, std::string(file) == "two.csv") << o.output;
  }
}

// `--resume FOLDER` with other data than the folder's said "resuming..." and replaced the finished result's files
// (issue 65): the folder's job_inputs.txt is checked before any work, naming what differs.
TEST(CliEdges, AResumeWithOtherInputsIsRefused) {
  const fs::path dir = dem::test::scratch_dir("cli_resume_inputs");
  const fs::path folder = dir / "calibrate_20990101-000000";
  fs::create_directories(folder);
  std::ofstream(folder / "job_inputs.txt") << "data 0\n--material S-1\n";
  const std::string job = "calibrate data/tang2025_table6_peak.csv --config configs/calibration/base.toml "
                          "--predict none -j 1 --plan --resume " + folder.string();
  Outcome o = triaxdem(job + " --material S-1", dir);
  EXPECT_NE(o.code, 0) << o.output;
  EXPECT_NE(o.output.find("calibrate_20990101-000000: the calibrate there ran with another data file (its bytes differ "
                          "from data/tang2025_table6_peak.csv)"), std::string::npos) << o.output;
  std::ofstream(folder / "job_inputs.txt") << "--material S-1\n";
  o = triaxdem(job + " --material S-2", dir);
  EXPECT_NE(o.output.find("ran with another --material ('S-1', now 'S-2')"), std::string::npos) << o.output;
  o = triaxdem(job + " --material S-1", dir);
  EXPECT_EQ(o.code, 0) << o.output;
  std::ofstream(folder / "job_inputs.txt") << "--compression 0\n";  // the first job fitted compression tests too
  o = triaxdem(job + " --material S-1", dir);
  EXPECT_NE(o.output.find("ran with another --compression file (its bytes differ from none)"), std::string::npos)
      << o.output;
}

// --hold-out leaves a pressure out of the fit and predicts it: the plan fits the other two tests and predicts all three;
// a pressure the data lack, one that would leave a material nothing to fit, one --material's material lacks, or no
// pressure at all (nan, inf, negative) is refused before any work, naming the file, the option and the pressures.
TEST(CliEdges, AHeldOutPressureIsLeftOutOfTheFitAndPredicted) {
  const fs::path dir = dem::test::scratch_dir("cli_hold_out");
  {
    std::ofstream d(dir / "d.csv");
    d << "material,sigma3_kPa,eps_a_pct,q_kPa,eps_v_pct\n";
    for (int s3 : {100, 200, 300})
      d << "A," << s3 << ",0,0,0\nA," << s3 << ",1," << 0.6 * s3 << ",0.1\nA," << s3 << ",2," << 0.7 * s3
        << ",-0.1\nA," << s3 << ",3," << 0.65 * s3 << ",-0.3\n";
    d << "B,300,0,0,0\nB,300,1,180,0.1\nB,300,2,210,-0.1\nB,300,3,195,-0.3\n";
  }
  const std::string job = "calibrate " + (dir / "d.csv").string() +
                          " --config configs/calibration/base.toml --predict configs/small/S1_100kPa.toml -j 1 --plan -o " +
                          (dir / "out").string();
  const Outcome held = triaxdem(job + " --material A --hold-out 300", dir);
  EXPECT_EQ(held.code, 0) << held.output;
  for (const std::string& said : {std::string("A: search: 22 points x 2 tests"), std::string("1 held out")})
    EXPECT_NE(held.output.find(said), std::string::npos) << said << "\n" << held.output;
  const Outcome missing = triaxdem(job + " --material A --hold-out 250", dir);
  EXPECT_EQ(missing.code, 1) << missing.output;
  EXPECT_NE(missing.output.find("d.csv: --hold-out 250 kPa: no test at that pressure (the data's, kPa: 100, 200, 300)"),
            std::string::npos) << missing.output;
  const Outcome alone = triaxdem(job + " --hold-out 300", dir);
  EXPECT_EQ(alone.code, 1) << alone.output;
  EXPECT_NE(alone.output.find("--hold-out 300 kPa: material B has no other test to fit"), std::string::npos)
      << alone.output;
  // Issue 87: a pressure of another material than --material's held nothing out while saying it did; nan and inf held
  // nothing out in silence.
  const Outcome other = triaxdem(job + " --material B --hold-out 100", dir);
  EXPECT_EQ(other.code, 1) << other.output;
  EXPECT_NE(other.output.find("d.csv: --hold-out 100 kPa: material B has no test at that pressure (its pressures, kPa: "
                              "300)"), std::string::npos) << other.output;
  std::vector<Outcome> outcomes{missing, alone, other};
  for (const char* v : {"nan", "inf", "-100"}) {
    outcomes.push_back(triaxdem(job + " --material A --hold-out " + v, dir));
    EXPECT_NE(outcomes.back().code, 0) << v << "\n" << outcomes.back().output;
    EXPECT_NE(outcomes.back().output.find(std::string(v) + " is no confining pressure (kPa, a number above 0)"),
              std::string::npos) << outcomes.back().output;
  }
  for (const Outcome& o : outcomes)
    EXPECT_EQ(o.output.find("plan (before any packing)"), std::string::npos) << o.output;
}

// Issue 87: data of a specimen smaller than the simulator's cell (10 balls against 120) were accepted, and the cell's
// bias check extrapolated "to a specimen of 10 balls" (q -45%): refused before any work, naming the file, the test,
// both sizes and the key; data of the cell's size plan.
TEST(CliEdges, DataOfASpecimenSmallerThanTheCellAreRefused) {
  const fs::path dir = dem::test::scratch_dir("cli_small_specimen");
  for (const char* balls : {"10", "120"}) {
    std::ofstream(dir / "d.csv") << "material,sigma3_kPa,eps_a_pct,q_kPa,eps_v_pct,specimen_balls\n"
                                 << "A,100,0,0,0," << balls << "\nA,100,1,60,0.1," << balls << "\nA,100,2,70,-0.1,"
                                 << balls << "\nA,100,3,65,-0.3," << balls << "\n";
    const Outcome o = triaxdem("calibrate " + (dir / "d.csv").string() + " --config tests/data/hidden_effects.toml "
                               "--predict none -j 1 --plan -o " + (dir / "out").string(), dir);
    const bool refused = std::string(balls) == "10";
    EXPECT_EQ(o.code, refused ? 1 : 0) << o.output;
    EXPECT_EQ(o.output.find("d.csv: specimen_balls 10 (A at 100 kPa) is below the 120 balls of the simulator's cell "
                            "(tests/data/hidden_effects.toml: [particles] count)") != std::string::npos, refused)
        << o.output;
    EXPECT_EQ(o.output.find("plan (before any packing)") == std::string::npos, refused) << o.output;
  }
}

// Two fidelities correct the cell toward the membrane template's test, so it must be the data's size: data from
// specimens of 1,000 balls against the small S-1 template (3,662) are refused before any work, naming the key and both
// sizes; data of the template's size plan.
TEST(CliEdges, ATwoFidelityTemplateOfAnotherSizeIsRefusedBeforeAnyWork) {
  const fs::path dir = dem::test::scratch_dir("cli_template_size");
  for (const char* balls : {"1000", "3662"}) {
    std::ofstream(dir / "d.csv") << "material,sigma3_kPa,eps_a_pct,q_kPa,eps_v_pct,specimen_balls\n"
                                 << "A,100,0,0,0," << balls << "\nA,100,1,60,0.1," << balls << "\nA,100,2,70,-0.1,"
                                 << balls << "\nA,100,3,65,-0.3," << balls << "\n";
    const Outcome o = triaxdem("calibrate " + (dir / "d.csv").string() + " --config configs/calibration/base.toml "
                               "--reference-test two_fidelity --predict configs/small/S1_100kPa.toml -j 1 --plan -o " +
                               (dir / "out").string(), dir);
    const bool refused = std::string(balls) == "1000";
    EXPECT_EQ(o.code, refused ? 1 : 0) << o.output;
    EXPECT_EQ(o.output.find("--predict: two fidelities correct the cell toward the membrane test of "
                            "configs/small/S1_100kPa.toml, whose specimen has 3662 balls where the data's (A at 100 kPa) "
                            "have 1000") != std::string::npos, refused) << o.output;
    EXPECT_EQ(o.output.find("plan (before any packing)") == std::string::npos, refused) << o.output;
  }
}

// Issue 87: a hertz_mindlin template beside an rrlinear base ran the two fidelities' loop to a "fixed point" without a
// note: refused before any work, naming the key, the template and both laws.
TEST(CliEdges, ATwoFidelityTemplateOfAnotherLawIsRefused) {
  const fs::path dir = dem::test::scratch_dir("cli_template_law");
  write_four_point_curve(dir / "d.csv");
  {
    std::ifstream in(std::string(TRIAXDEM_SOURCE_DIR) + "/configs/small/S1_100kPa.toml");
    std::ofstream out(dir / "hm.toml");
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("emod_Pa", 0) == 0 || line.rfind("kratio", 0) == 0) continue;
      out << line << "\n";
      if (line.rfind("[material]", 0) == 0) out << "law = \"hertz_mindlin\"\nshear_modulus_Pa = 1.5e9\npoisson = 0.3\n";
    }
  }
  const Outcome o = triaxdem("calibrate " + (dir / "d.csv").string() + " --config configs/calibration/base.toml "
                             "--reference-test two_fidelity --predict " + (dir / "hm.toml").string() +
                             " -j 1 --plan -o " + (dir / "out").string(), dir);
  EXPECT_EQ(o.code, 1) << o.output;
  EXPECT_NE(o.output.find("hm.toml, whose contact law is hertz_mindlin where the base's (configs/calibration/base.toml) "
                          "is rrlinear"), std::string::npos) << o.output;
  EXPECT_EQ(o.output.find("plan (before any packing)"), std::string::npos) << o.output;
}

// A plan beyond the bound (four hours here) is refused before any packing unless --yes is given, naming its costliest
// stage and the setting that sizes it; 64 scatter specimens of 32,000 balls with an "auto" ensemble are such a job:
// its plan takes up to 15 to 27 hours at 152 to 265 ns a particle-step (this machine idle and busy), so a machine
// four times faster is still refused. The plan's times follow the speed measured on the machine at hand: a job
// sized near the bound is refused on a busy machine and runs on an idle one.
TEST(CliEdges, AJobBeyondItsBoundAsksForYes) {
  const fs::path dir = dem::test::scratch_dir("cli_plan_bound");
  write_four_point_curve(dir / "d.csv");
  {
    std::ifstream in(std::string(TRIAXDEM_SOURCE_DIR) + "/tests/data/hidden_effects.toml");
    std::ofstream out(dir / "big.toml");
    std::string line;
    while (std::getline(in, line)) {
      if (line.rfind("count = ", 0) == 0) line = "count = 32000";
      if (line.rfind("size_mm = ", 0) == 0) line = "size_mm = [92.07, 92.07, 92.07]";
      if (line.rfind("ensemble = ", 0) == 0) line = "ensemble = \"auto\"";
      if (line.rfind("scatter_specimens = ", 0) == 0) line = "scatter_specimens = 64";
      out << line << "\n";
    }
  }
  const Outcome o = triaxdem("calibrate " + (dir / "d.csv").string() + " --config " + (dir / "big.toml").string() +
                             " --predict none -j 1 -o " + (dir / "out").string(), dir);
  EXPECT_EQ(o.code, 1) << o.output;
  EXPECT_NE(o.output.find("run it with --yes, or make it smaller; its costliest stage is A: search"),
            std::string::npos) << o.output;
  EXPECT_NE(o.output.find("sized by [calibrate] ensemble (auto)"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("; a run of "), std::string::npos) << "a run's length is said beside the stage\n" << o.output;
  EXPECT_EQ(o.output.find("triaxdem: packing"), std::string::npos) << o.output;
  EXPECT_EQ(o.output.find("matching the void ratio"), std::string::npos) << o.output;
  EXPECT_FALSE(fs::exists(dir / "out") && !fs::is_empty(dir / "out"));
  // Issue 87: --yes started a job planned at 1,454 hours. The same job at a hundredth of the inertial number (a hundred
  // times the steps: 1,500 to 2,700 hours) is refused with --yes too, beyond a week.
  {
    std::ifstream in(dir / "big.toml");
    std::ofstream out(dir / "slow.toml");
    std::string line;
    while (std::getline(in, line)) out << (line.rfind("target_inertial = ", 0) == 0 ? "target_inertial = 3e-5" : line) << "\n";
  }
  const Outcome slow = triaxdem("calibrate " + (dir / "d.csv").string() + " --config " + (dir / "slow.toml").string() +
                                " --predict none -j 1 --yes -o " + (dir / "out").string(), dir);
  EXPECT_EQ(slow.code, 1) << slow.output;
  EXPECT_NE(slow.output.find("beyond what --yes starts: make it smaller, or spread it over ranks"), std::string::npos)
      << slow.output;
  EXPECT_EQ(slow.output.find("triaxdem: packing"), std::string::npos) << slow.output;
}

// A prediction of the walled cell beside a walled reference would compare the cell with itself: refused before any
// run or folder, naming the option and what to give instead.
TEST(CliEdges, AWalledPredictionOfAWalledCalibrationIsRefused) {
  const fs::path dir = dem::test::scratch_dir("cli_predict_walls");
  write_four_point_curve(dir / "d.csv");
  const Outcome o = triaxdem("calibrate " + (dir / "d.csv").string() + " --config tests/data/hidden_effects.toml "
                             "--reference-test walls --predict walls -j 1 -o " + (dir / "out").string(), dir);
  EXPECT_EQ(o.code, 1) << o.output;
  EXPECT_NE(o.output.find("--predict: walls: the reference test is the cell between six walls already"),
            std::string::npos) << o.output;
  EXPECT_FALSE(fs::exists(dir / "out") && !fs::is_empty(dir / "out")) << "a refused calibration left a folder";
}

// The periodic job's time line read "membrane 0.0 s, walls 22.8 s" for a cell with neither: the stage is called
// boundaries (the cell's stretch, walls or membrane nodes), and the membrane's time shows only where it ran.
TEST(CliEdges, TheTimeLineNamesOnlyStagesThatRan) {
  dem::StageTimes t;
  t.boundaries = 1.25;
  std::string line = dem::describe(t, 1000, 10);
  EXPECT_NE(line.find("boundaries 1.2 s"), std::string::npos) << line;
  EXPECT_EQ(line.find("membrane"), std::string::npos) << line;
  EXPECT_EQ(line.find("walls"), std::string::npos) << line;
  t.membrane = 2;
  line = dem::describe(t, 1000, 10);
  EXPECT_NE(line.find("membrane 2.0 s"), std::string::npos) << line;
}

// calibrate and diagnose wrote nothing until they ended and could not resume: each run's curves are stored in the
// result folder as the run ends, and --resume reads them. With half of them gone (a calibration killed part way),
// the resumed one runs only the missing ones and ends with the same results, to the byte. It runs once (not again
// at two threads): the program it starts runs at one thread either way.
TEST(CliEdges, ACalibrationResumesFromItsStoredRuns) {
  const fs::path dir = dem::test::scratch_dir("cli_resume_calibration");
  std::string base = text_of(fs::path(TRIAXDEM_SOURCE_DIR) / "tests/data/hidden_effects.toml");
  for (const auto& [key, value] : {std::pair<std::string, std::string>{"ensemble", "1"}, {"scatter_specimens", "2"},
                                   {"target_axial_strain_pct", "1.0"}}) {
    const auto at = base.find("\n" + key + " = ");
    ASSERT_NE(at, std::string::npos) << key;
    base.replace(at + 1, base.find('\n', at + 1) - at - 1, key + " = " + value);
  }
  std::ofstream(dir / "base.toml") << base;
  const std::string config = " --config " + (dir / "base.toml").string();
  Outcome o = triaxdem("synth" + config + " -o " + (dir / "data.csv").string() + " --extension none --seed 1 "
                       "--pressures 100", dir);
  ASSERT_EQ(o.code, 0) << o.output;
  // synth ran 49 s in silence (issue 65): its first line says what it runs and about how long it takes.
  EXPECT_NE(o.output.find("synth: 1 tests of"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find(" on this machine\n"), std::string::npos) << o.output;
  // The data without their void ratio: no state match, whose packings took 34 of a calibration's 38 s; the run store
  // and its resumption are what this test checks, and the cell-bias check (specimen_balls kept) still stores runs.
  {
    std::istringstream in(text_of(dir / "data.csv"));
    std::ostringstream out;
    int drop = -1;
    for (std::string line; std::getline(in, line);) {
      if (line.empty() || line[0] == '#') {
        out << line << "\n";
        continue;
      }
      std::vector<std::string> cells;
      std::istringstream cs(line);
      for (std::string c; std::getline(cs, c, ',');) cells.push_back(c);
      if (drop < 0) drop = static_cast<int>(std::find(cells.begin(), cells.end(), "void_ratio") - cells.begin());
      ASSERT_LT(drop, static_cast<int>(cells.size())) << "no void_ratio column in " << line;
      cells.erase(cells.begin() + drop);
      for (std::size_t k = 0; k < cells.size(); ++k) out << (k ? "," : "") << cells[k];
      out << "\n";
    }
    std::ofstream(dir / "data.csv") << out.str();
  }
  const std::string calibrate = "calibrate " + (dir / "data.csv").string() + config + " --predict none -j 1 ";
  o = triaxdem(calibrate + "-o " + (dir / "out").string(), dir);
  ASSERT_EQ(o.code, 0) << o.output;
  fs::path folder;
  for (const auto& e : fs::directory_iterator(dir / "out"))  // beside it, the packing store's .specimens
    if (e.path().filename().string().rfind("calibrate_", 0) == 0) folder = e.path();
  std::vector<fs::path> runs;
  for (const auto& e : fs::directory_iterator(folder / "runs")) runs.push_back(e.path());
  ASSERT_GT(runs.size(), 20u) << "each run stored as it ended";
  std::map<std::string, std::string> first;
  for (const char* f : {"calibrated.csv", "errors.csv", "simulated_curves.csv"}) first[f] = text_of(folder / f);
  std::sort(runs.begin(), runs.end());
  for (std::size_t k = 0; k < runs.size(); k += 2) fs::remove(runs[k]);
  o = triaxdem(calibrate + "--resume " + folder.string(), dir);
  ASSERT_EQ(o.code, 0) << o.output;
  EXPECT_NE(o.output.find("resuming in " + folder.string() + ": the runs stored there are read"), std::string::npos)
      << o.output;
  // The store also holds the cell-bias check's runs: of the search's, those left are read, the others run again.
  EXPECT_NE(o.output.find(" of them read from the run store)"), std::string::npos) << o.output;
  const auto at = o.output.find("read from the run store)");
  const long total = std::stol(o.output.substr(o.output.rfind("calibrate: ", at) + 11));
  const long read = std::stol(o.output.substr(o.output.rfind("runs (", at) + 6));
  EXPECT_GT(read, 0);
  EXPECT_LT(read, total) << "only the missing runs run again";
  for (const auto& [f, text] : first) EXPECT_EQ(text_of(folder / f), text) << f;
  o = triaxdem(calibrate + "--resume " + (dir / "out").string(), dir);
  EXPECT_EQ(o.code, 1);
  EXPECT_NE(o.output.find("not a calibrate_<date> folder of an earlier calibrate"), std::string::npos) << o.output;
}
