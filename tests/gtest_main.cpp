#include <gtest/gtest.h>
#include <Kokkos_Core.hpp>

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  // ctest discovers the tests by listing them: without Kokkos, whose start-up warnings on stdout would
  // otherwise be read as test names.
  if (::testing::GTEST_FLAG(list_tests)) return RUN_ALL_TESTS();
  Kokkos::ScopeGuard guard(argc, argv);
  return RUN_ALL_TESTS();
}
