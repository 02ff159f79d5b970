// SPDX-License-Identifier: Apache-2.0
// The camera-based calibration measured against the virtual rig's ground truth (rig_bridge.h).
#include "appliance/autocal/autocal.h"

#include <cstdlib>

#include <gtest/gtest.h>

#include "appliance/autocal/rig_bridge.h"
#include "appliance/rig/rig_file.h"

namespace mogao::autocal {
namespace {

rig::VirtualRig load(const std::string& name) {
    return rig::load_rig(std::string(MOGAO_SOURCE_DIR) + "/rigs/" + name + ".toml");
}

TEST(Autocal, StandardRigAccuracyAgainstGroundTruth) {
    const double scale = std::getenv("MOGAO_AUTOCAL_SCALE") ? std::atof(std::getenv("MOGAO_AUTOCAL_SCALE")) : 0.5;
    const rig::VirtualRig rig = scaled_rig(load("standard"), scale, scale);
    RigPatternSource source(rig);
    const AutocalResult r = calibrate(source, prior_from_rig(rig), {1920, 1080});
    const GeometryError g = measure_geometry(rig, r.calibration, 4);
    const LuminanceError l = measure_luminance(rig, r.calibration);
    std::printf("edge points %d rms %.3f mm, camera error %.2f mm; captures %d\n", r.report.edge_points,
                r.report.edge_rms_m * 1e3, (r.report.camera_position_m - rig.camera.pose.position_m).norm() * 1e3,
                r.report.captures);
    for (const ProjectorReport& p : r.report.projectors) {
        std::printf("%s bits %d/%d cells %d rms %.3f px angle %.1f\n", p.id.c_str(), p.column_bits, p.row_bits, p.cells,
                    p.rms_px, p.mean_view_angle_deg);
    }
    std::printf(
        "geometry: samples %d missing %d mean %.3f p95 %.3f max %.3f px (scale %.2f); luminance max %.4f seam %.4f\n",
        g.samples, g.missing, g.mean_px, g.p95_px, g.max_px, scale, l.max_deviation, l.seam_max_deviation);
    // Issue 13's goals, in projector pixels against the rig's ground truth: mean <= 0.3 px,
    // p95 <= 0.8 px; seam luminance deviation <= 1 % (measured at scale 0.5: mean 0.18, p95 0.25,
    // seam 0.83 %; at scale 1: mean 0.10, p95 0.27, seam 0.54 %).
    EXPECT_LE(g.mean_px, 0.3);
    EXPECT_LE(g.p95_px, 0.8);
    EXPECT_LT(g.missing + g.outside, g.samples / 100);
    EXPECT_LE(l.seam_max_deviation, 0.01);
    EXPECT_LE(l.max_deviation, 0.01);
}

TEST(Autocal, RefusesAProjectorTheCameraBarelySees) {
    rig::VirtualRig rig = scaled_rig(load("standard"), 0.25, 0.5);
    rig.projectors[2].pose.yaw_deg = -120.0;  // a sliver of it on the arc's end
    RigPatternSource source(rig);
    try {
        (void)calibrate(source, prior_from_rig(rig), {960, 540});
        FAIL() << "calibrated a projector the camera barely sees";
    } catch (const CalibrationRefused& e) {
        EXPECT_NE(std::string(e.what()).find("proj2"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace mogao::autocal
