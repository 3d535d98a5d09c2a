// The process pool of the calibration's parallel runs (host/util/forked_runs.hpp).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <vector>

#include "host/util/forked_runs.hpp"
#include "test_util.hpp"

using namespace dem;

// The next piece starts as soon as any running one ends: the pool ran in rounds, each waiting for its slowest
// piece. Piece 0 waits (up to 10 s) for a sign that piece 2 has started, which in rounds of two would come only
// after piece 0 had ended; pieces 1 and 2 end at once. Each result lands in its own place, whichever ends first.
TEST(ForkedRuns, TheNextPieceStartsWhenAnyEnds) {
  const std::filesystem::path sign = test::scratch_dir("forked_runs") / "piece_2_started";
  std::filesystem::remove(sign);
  std::vector<int> got(3, -1);
  forked_runs(
      3, 2,
      [&](std::size_t j, int fd) {
        int saw = 1;
        if (j == 2) std::ofstream(sign) << "started\n";
        if (j == 0) {
          saw = 0;
          for (int t = 0; t < 200 && !saw; ++t) {
            saw = std::filesystem::exists(sign) ? 1 : 0;
            if (!saw) ::usleep(50000);
          }
        }
        const int value = 10 * static_cast<int>(j + 1) + saw;
        put_bytes(fd, &value, sizeof value);
      },
      [&](std::size_t j, int fd) { return get_bytes(fd, &got[j], sizeof(int)); }, "pool test");
  EXPECT_EQ(got, (std::vector<int>{11, 21, 31})) << "10 x (piece + 1), plus 1 where piece 0 saw piece 2 start";
}

// The prediction's membrane tests ran 19 minutes before their first line (a specimen's build and its tests in each
// child): a piece that runs long is reported while it runs. Two pieces of 2.5 s under a 1 s period: each is reported
// at 1 and 2 s (up to 3 times on a loaded machine), and their results still come back.
TEST(ForkedRuns, PiecesThatRunLongAreReportedWhileTheyRun) {
  std::vector<int> got(2, -1), seen(2, 0);
  forked_runs(
      2, 2,
      [](std::size_t j, int fd) {
        ::usleep(2500000);
        const int value = static_cast<int>(j) + 1;
        put_bytes(fd, &value, sizeof value);
      },
      [&](std::size_t j, int fd) { return get_bytes(fd, &got[j], sizeof(int)); }, "pool test",
      [&](std::size_t j) { ++seen[j]; }, 1);
  EXPECT_EQ(got, (std::vector<int>{1, 2}));
  for (int s : seen) {
    EXPECT_GE(s, 2);
    EXPECT_LE(s, 3);
  }
}
