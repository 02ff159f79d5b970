// SPDX-License-Identifier: Apache-2.0
// GoogleTest main for every mogao test binary. Same as gtest_main, except that a run in which every
// selected test was skipped (GTEST_SKIP, e.g. the real scans in ../shared/data are absent) exits
// with 77, the conventional "skipped" code CTest is told about (SKIP_RETURN_CODE 77), so a skip is
// reported as a skip and never as a pass.
#include <gtest/gtest.h>

int main(int argc, char** argv) {
    testing::InitGoogleTest(&argc, argv);
    const int result = RUN_ALL_TESTS();
    const testing::UnitTest& unit = *testing::UnitTest::GetInstance();
    if (result == 0 && unit.test_to_run_count() > 0 && unit.skipped_test_count() == unit.test_to_run_count()) return 77;
    return result;
}
