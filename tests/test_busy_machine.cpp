/// The note a run prints before its work where its threads must share their cores (host/util/busy_machine.hpp).
#include <gtest/gtest.h>

#include <string>

#include "host/util/busy_machine.hpp"

using dem::busy_machine_note;

// Two threads on two cores beside a load of two (a calibration's workers): noted, with the binding and the way out;
// the same threads on an idle machine, or one thread on a busy one, are not.
TEST(BusyMachine, ThreadsThatMustShareTheirCoresAreNoted) {
  const std::string bound = busy_machine_note(2.1, 2, 2, "spread");
  EXPECT_NE(bound.find("load 2.1 on 2 cores"), std::string::npos) << bound;
  EXPECT_NE(bound.find("OMP_PROC_BIND=spread, share"), std::string::npos) << bound;
  EXPECT_NE(bound.find("OMP_NUM_THREADS=1 and OMP_PROC_BIND unset"), std::string::npos) << bound;
  const std::string free = busy_machine_note(2.1, 2, 2, nullptr);
  EXPECT_FALSE(free.empty());
  EXPECT_EQ(free.find("OMP_PROC_BIND"), std::string::npos) << free;
  EXPECT_EQ(busy_machine_note(2.1, 2, 2, "false").find("OMP_PROC_BIND"), std::string::npos);
  EXPECT_EQ(busy_machine_note(0.3, 2, 2, "spread"), "");  // idle: the shell's own load is slack
  EXPECT_EQ(busy_machine_note(3.0, 2, 1, "spread"), "");  // one thread waits for no other
  EXPECT_EQ(busy_machine_note(0.5, 2, 2, nullptr), "") << "within half a core of slack";
  EXPECT_FALSE(busy_machine_note(0.6, 2, 2, nullptr).empty()) << "beyond it";
  EXPECT_FALSE(busy_machine_note(6.0, 8, 4, nullptr).empty());  // 6 + 4 threads on 8 cores
}
