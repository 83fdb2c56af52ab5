// main() for test binaries that CTest runs whole (the process tests, wrapped in a private
// network namespace): exits 77 when no test failed and at least one was skipped, so that CTest
// (SKIP_RETURN_CODE 77) shows the binary as skipped instead of passed. Discovered tests need
// none of this: gtest_discover_tests marks a skipped case by its output.
#include <gtest/gtest.h>

#include <iostream>

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  const int failed = RUN_ALL_TESTS();
  const testing::UnitTest& unit = *testing::UnitTest::GetInstance();
  if (failed != 0 || unit.skipped_test_count() == 0) return failed;
  std::cout << "[  SKIPPED ] " << unit.skipped_test_count() << " of " << unit.test_to_run_count()
            << " tests skipped: reported to CTest as skipped\n";
  return 77;
}
