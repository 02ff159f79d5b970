// SPDX-License-Identifier: Apache-2.0
// The calibration store: the last good calibration is kept, and a write interrupted at any point
// (the writing process killed) leaves a complete, readable calibration at the path.
#include "appliance/selfcal/calibration_store.h"

#include <chrono>
#include <csignal>
#include <filesystem>
#include <thread>

#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "appliance/warp/ideal_calibration.h"

namespace mogao::selfcal {
namespace {

ScreenCalibration calibration_with_overlap(double overlap, ImageSize output) {
    IdealCalibrationParams p;
    p.overlap = overlap;
    p.output = output;
    return make_ideal_calibration(p);
}

double overlap_of(const ScreenCalibration& c) {
    // The first projector's warp u at its last column tells the layout apart.
    const ProjectorCalibration& p = c.projectors[0];
    return p.warp.uv[2 * static_cast<std::size_t>(p.warp.size.width - 1)];
}

std::filesystem::path temp_dir(const std::string& name) {
    const auto d =
        std::filesystem::temp_directory_path() / ("mogao-selfcal-" + name + "-" + std::to_string(::getpid()));
    std::filesystem::remove_all(d);
    std::filesystem::create_directories(d);
    return d;
}

TEST(CalibrationStore, KeepsTheLastGoodOne) {
    const auto dir = temp_dir("keep");
    const auto path = dir / "calibration.mpcdi";
    const ScreenCalibration a = calibration_with_overlap(0.1, {64, 48});
    const ScreenCalibration b = calibration_with_overlap(0.3, {64, 48});
    save_calibration(path, a);
    EXPECT_FALSE(std::filesystem::exists(last_good_path(path)));
    save_calibration(path, b);
    EXPECT_NEAR(overlap_of(load_calibration(path)), overlap_of(b), 1e-5);
    EXPECT_NEAR(overlap_of(load_calibration(last_good_path(path))), overlap_of(a), 1e-5);
    // An invalid calibration is refused before anything is touched.
    ScreenCalibration bad = b;
    bad.projectors[0].warp.uv.pop_back();
    EXPECT_ANY_THROW(save_calibration(path, bad));
    EXPECT_NEAR(overlap_of(load_calibration(path)), overlap_of(b), 1e-5);
    EXPECT_NEAR(overlap_of(load_calibration(last_good_path(path))), overlap_of(a), 1e-5);
    std::filesystem::remove_all(dir);
}

TEST(CalibrationStore, AWriteKilledMidwayLeavesTheLastGoodCalibration) {
    const auto dir = temp_dir("kill");
    const auto path = dir / "calibration.mpcdi";
    const ScreenCalibration a = calibration_with_overlap(0.1, {320, 240});
    const ScreenCalibration b = calibration_with_overlap(0.3, {320, 240});
    save_calibration(path, b);
    save_calibration(path, a);  // now a last good one exists too
    // A child writes b again and again; it is killed (SIGKILL: no cleanup) after a varying delay,
    // so the kill lands at different points of the write. The file must always read back whole.
    int killed_while_writing = 0;
    for (int trial = 0; trial < 8; ++trial) {
        const pid_t pid = ::fork();
        ASSERT_GE(pid, 0);
        if (pid == 0) {
            for (;;) save_calibration(path, (trial % 2) != 0 ? a : b);
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(5 + 11 * trial));
        ::kill(pid, SIGKILL);
        int status = 0;
        ::waitpid(pid, &status, 0);
        if (WIFSIGNALED(status)) ++killed_while_writing;
        const ScreenCalibration read = load_calibration(path);
        const double o = overlap_of(read);
        EXPECT_TRUE(std::abs(o - overlap_of(a)) < 1e-5 || std::abs(o - overlap_of(b)) < 1e-5) << o;
        (void)load_calibration(last_good_path(path));
    }
    EXPECT_EQ(killed_while_writing, 8);
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace mogao::selfcal
