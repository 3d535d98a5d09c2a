/// Checkpoints and resume. A resumed run must be the run that was not stopped, bit for bit: the
/// comparisons below are exact (==), since any difference, however small, grows in a chaotic granular
/// system and would make a resumed study differ from an unstopped one.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "host/engine/checkpoint.hpp"
#include "host/config/config.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/cli/job.hpp"
#include "host/engine/setup.hpp"
#include "test_util.hpp"

extern char** environ;

using namespace dem;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) { return dem::test::scratch_dir("checkpoint/" + name); }

/// 300 beads poured into a box under a strong gravity (200 g, so that they land within a few thousand
/// steps) with sliding, rolling and twisting friction and slip weakening: by step 4000 the contacts carry shear and
/// rolling history and every history slot (contact_params.hpp).
Config pour(const fs::path& dir, long steps, long checkpoint_every = 0) {
  const fs::path file = dir / "pour.toml";
  std::ofstream(file) << "[run]\nname = \"pour\"\nseries_every = 100\nsnapshot_every = 1000\n"
                         "[particles]\ncount = 300\ndiameter_mm = 2.0\n"
                         "[box]\nsize_mm = [14.0, 14.0, 24.0]\nwalls = true\nfill = \"random\"\n"
                         "[material]\nemod_Pa = 1.0e8\nkratio = 1.5\nmu_s = 0.3\nmu_r = 0.05\n"
                         "wear = 0.3\ntwist = 0.1\n"
                         "[solver]\ndamping = 0.3\ngravity = [0.0, 0.0, -2000.0]\ndt_safety = 0.2\n";
  Config c = load_config(file.string());
  c.run.steps = steps;
  c.run.output = (dir / "out").string();
  c.run.checkpoint_every = checkpoint_every;
  c.run.checkpoint_minutes = 0;
  return c;
}

void expect_same(const SimState& a, const SimState& b) {
  EXPECT_EQ(a.step, b.step);
  EXPECT_EQ(a.time, b.time);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.v, b.v);
  EXPECT_EQ(a.w, b.w);
  EXPECT_EQ(a.x_ref, b.x_ref);
  EXPECT_EQ(a.gid, b.gid);
  for (const auto& [p, q] : {std::make_pair(&a.balls, &b.balls), std::make_pair(&a.walls, &b.walls)}) {
    EXPECT_EQ(p->key, q->key);
    EXPECT_EQ(p->fs, q->fs);
    EXPECT_EQ(p->mr, q->mr);
    EXPECT_EQ(p->slot, q->slot);
    EXPECT_EQ(p->flags, q->flags);
  }
  EXPECT_EQ(a.wall_point, b.wall_point);
  EXPECT_EQ(a.wall_disp, b.wall_disp);
  EXPECT_EQ(a.stats.max_disp2, b.stats.max_disp2);
}

/// Contacts that carry shear history (a nonzero tangential spring): without them the test could not fail
/// on lost history.
int with_history(const SavedContacts& c) {
  int n = 0;
  for (std::size_t k = 0; k < c.key.size(); ++k)
    n += c.fs[3 * k] != 0 || c.fs[3 * k + 1] != 0 || c.fs[3 * k + 2] != 0;
  return n;
}

std::string text_of(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The triaxdem program, run as a child process (spawned: a fork of this multi-threaded test would not be safe).
pid_t spawn_triaxdem(const std::vector<std::string>& args, const fs::path& log) {
  std::vector<std::string> all{dem::test::triaxdem_binary()};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  return rc == 0 ? pid : -1;
}

int wait_exit(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : WIFSIGNALED(status) ? 128 + WTERMSIG(status) : -1;
}

/// Writes the config of `c` as a file the child can read: the test's text plus its run keys.
fs::path config_file(const Config& c, const fs::path& dir) {
  const fs::path file = dir / "child.toml";
  std::string text = text_of(dir / "pour.toml");
  const std::string run = "[run]\n";
  text.replace(text.find(run), run.size(),
               run + "steps = " + std::to_string(c.run.steps) + "\noutput = \"" + c.run.output +
                   "\"\ncheckpoint_every = " + std::to_string(c.run.checkpoint_every) + "\ncheckpoint_minutes = 0\n");
  std::ofstream(file) << text;
  return file;
}

}  // namespace

// Every field of the state, history included, comes back from the file as it went in.
TEST(Checkpoint, FileHoldsTheStateExactly) {
  const fs::path dir = scratch("file");
  auto sim = build_simulation(pour(dir, 0), false);
  sim->run(4000);
  Checkpoint c;
  c.job = "test";
  c.sim = sim->state();
  c.numbers["series"] = {1.5, -2, 1e-300};
  c.texts["index"] = "line one\nline two\n";
  ASSERT_GT(with_history(c.sim.balls), 10);
  for (int s = 0; s < kHistorySlots; ++s)
    ASSERT_GT(std::count_if(c.sim.balls.slot[s].begin(), c.sim.balls.slot[s].end(), [](double v) { return v != 0; }), 10)
        << "test set-up: history in slot " << kHistorySlotNames[s];
  write_checkpoint(checkpoint_path(dir.string()), c);
  const Checkpoint r = read_checkpoint(checkpoint_path(dir.string()));
  EXPECT_EQ(r.job, "test");
  expect_same(c.sim, r.sim);
  EXPECT_EQ(r.sim.f, c.sim.f);
  EXPECT_EQ(r.sim.mass, c.sim.mass);
  EXPECT_EQ(r.sim.specimen, c.sim.specimen);
  EXPECT_EQ(r.sim.balls.i, c.sim.balls.i);
  EXPECT_EQ(r.sim.walls.j, c.sim.walls.j);
  EXPECT_EQ(r.sim.fresh, c.sim.fresh);
  EXPECT_EQ(r.numbers, c.numbers);
  EXPECT_EQ(r.texts, c.texts);
  EXPECT_FALSE(fs::exists(checkpoint_path(dir.string()) + ".tmp"));
}

// 2N steps in one go against N steps, a checkpoint file, a new Simulation built from the config, N steps.
TEST(Checkpoint, ResumedSimulationIsTheUnstoppedOneBitForBit) {
  const fs::path dir = scratch("sim");
  const Config c = pour(dir, 0);
  const long n = 3000;
  auto whole = build_simulation(c, false);
  whole->run(2 * n);
  auto first = build_simulation(c, false);
  first->run(n);
  ASSERT_GT(with_history(first->state().balls), 10);
  write_checkpoint(checkpoint_path(dir.string()), Checkpoint{"test", first->state(), {}, {}});
  auto resumed = build_simulation(c, false);
  resumed->restore(read_checkpoint(checkpoint_path(dir.string())).sim);
  resumed->run(n);
  expect_same(whole->state(), resumed->state());
  EXPECT_GT(with_history(whole->state().balls), 10);
}

// A checkpoint of another system is refused, naming what differs.
TEST(Checkpoint, RestoreRefusesAnotherSystem) {
  const fs::path dir = scratch("other");
  Config c = pour(dir, 0);
  auto sim = build_simulation(c, false);
  const SimState s = sim->state();
  c.particles.count = 299;
  auto other = build_simulation(c, false);
  try {
    other->restore(s);
    FAIL() << "a state of 300 balls was restored into 299";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("balls: 300 in the saved state, 299 in this simulation"), std::string::npos)
        << e.what();
  }
}

// The run job end to end: 2N steps, against N steps and `--resume` to 2N: the same series and the same final
// particles; the snapshot index keeps the first run's final snapshot and adds the resumed run's.
TEST(Checkpoint, RunJobResumesItsSeriesAndSnapshots) {
  const fs::path a = scratch("job_a"), b = scratch("job_b");
  ASSERT_EQ(run_job(pour(a, 6000)), 0);
  ASSERT_EQ(run_job(pour(b, 3500)), 0);
  ASSERT_EQ(run_job(pour(b, 6000), true), 0);
  EXPECT_TRUE(text_of(a / "out" / "series.csv") == text_of(b / "out" / "series.csv"));
  const std::string index = text_of(b / "out" / "snapshots.xdmf");
  for (const char* snap : {"snap_000000000.h5", "snap_000003000.h5", "snap_000003500.h5", "snap_000006000.h5"})
    EXPECT_NE(index.find(snap), std::string::npos) << snap;
  const io::SnapshotFile fa = io::read_snapshot((a / "out" / "snap_000006000.h5").string());
  const io::SnapshotFile fb = io::read_snapshot((b / "out" / "snap_000006000.h5").string());
  EXPECT_EQ(fa.particles.x, fb.particles.x);
  EXPECT_GT(fa.particles.x.size(), 0u);
}

// Resume without a checkpoint says what to do.
TEST(Checkpoint, ResumeWithoutACheckpointSaysSo) {
  const fs::path dir = scratch("none");
  try {
    run_job(pour(dir, 100), true);
    FAIL() << "resumed from nothing";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("run without --resume"), std::string::npos) << e.what();
  }
}

namespace {
// A run killed with SIGKILL, or stopped by SIGTERM, 150 ms after its first checkpoint resumes to the end of the
// run that was never stopped. The killed run loses at most one checkpoint interval; its files stay readable and
// its series ends at its checkpoint (or one interval later, when the kill lands while the checkpoint is being
// written); SIGTERM writes a checkpoint at the step it arrives and exits 143. A run that ends before the signal
// fails the test: it would check nothing.
void signal_and_resume(int sig) {
  const long steps = 20000, every = 500;
  const fs::path ref = scratch(sig == SIGKILL ? "kill_ref" : "term_ref");
  ASSERT_EQ(run_job(pour(ref, steps)), 0);
  const std::string expected = text_of(ref / "out" / "series.csv");
  {
    const fs::path dir = scratch(sig == SIGKILL ? "killed" : "terminated");
    const Config c = pour(dir, steps, every);
    const fs::path cfg = config_file(c, dir);
    const pid_t pid = spawn_triaxdem({"run", cfg.string()}, dir / "first.log");
    ASSERT_GT(pid, 0);
    const fs::path ckpt = checkpoint_path(c.run.output);
    for (int k = 0; k < 2000 && !fs::exists(ckpt); ++k) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    ASSERT_TRUE(fs::exists(ckpt)) << text_of(dir / "first.log");
    const int delay = 150;
    std::this_thread::sleep_for(std::chrono::milliseconds(delay));
    kill(pid, sig);
    const int status = wait_exit(pid);
    SCOPED_TRACE("signal " + std::to_string(sig) + " after " + std::to_string(delay) + " ms; log: " +
                 text_of(dir / "first.log"));
    ASSERT_NE(status, 0) << "the run ended before the signal: make the run longer (steps) for this machine";
    EXPECT_EQ(status, 128 + sig);
    // Every file under its final name reads back; the series ends where the checkpoint is.
    const Checkpoint k = read_checkpoint(ckpt.string());
    if (sig == SIGKILL) EXPECT_EQ(k.sim.step % every, 0);  // the last of the regular checkpoints
    for (const auto& e : fs::directory_iterator(c.run.output))
      if (e.path().extension() == ".h5" && e.path().filename().string().rfind("snap_", 0) == 0)
        EXPECT_NO_THROW(io::read_snapshot(e.path().string())) << e.path();
    std::istringstream series(text_of(fs::path(c.run.output) / "series.csv"));
    std::string line, last;
    while (std::getline(series, line)) last = line;
    const long last_step = std::stol(last.substr(0, last.find(',')));
    if (sig == SIGKILL) {
      // The series is flushed just before each checkpoint is written, so a kill that lands while the checkpoint
      // is being written leaves the series one checkpoint interval ahead (a 1-in-4 event on this machine once
      // the loop ran at 8.6 M particle-steps/s); the resume rewrites it from the checkpoint (checked below).
      EXPECT_TRUE(last_step == k.sim.step / 100 * 100 || last_step == k.sim.step + every)
          << "series ends at " << last_step << ", checkpoint at " << k.sim.step;
    } else {
      EXPECT_EQ(last_step, k.sim.step / 100 * 100);
    }
    if (sig == SIGTERM) {
      // The checkpoint is taken at the step the signal arrived, so at most the step in progress is redone.
      EXPECT_NE(text_of(dir / "first.log").find("SIGTERM at step " + std::to_string(k.sim.step)), std::string::npos);
    }
    const pid_t again = spawn_triaxdem({"run", cfg.string(), "--resume"}, dir / "resume.log");
    ASSERT_EQ(wait_exit(again), 0) << text_of(dir / "resume.log");
    EXPECT_TRUE(text_of(fs::path(c.run.output) / "series.csv") == expected);
  }
}
}  // namespace

TEST(Checkpoint, KilledRunResumes) { signal_and_resume(SIGKILL); }

TEST(Checkpoint, TerminatedRunResumes) { signal_and_resume(SIGTERM); }
