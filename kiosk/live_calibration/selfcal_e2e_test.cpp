// SPDX-License-Identifier: Apache-2.0
// [selfcal] end to end through the real `mogao-kiosk` binary: headless outputs (Mesa surfaceless
// EGL), an MPCDI calibration and its models file as `mogao-calibrate-sim rig` writes them (here
// built from the standard virtual rig's exact models at half resolution, as the existing
// selfcal_kiosk_test does), the real link (gRPC + mutual TLS over [::1]) to a TEST DOUBLE of the
// farm -- a LinkServer whose renderer answers every view request with the same textured content
// frame instead of rendering a scene -- and the screen camera "rig:<bumped rig>": a SIMULATION of
// the camera seeing the rig's projectors with the middle one knocked by 1 degree of yaw.
// The rig is rigs/colour.toml (the standard geometry with projectors of different brightness,
// colour temperature, gamma and black level) and the calibration carries its measured colour
// (per-channel response LUTs, black-level beta maps, scaled blends: selfcal::colour_of_rig, what
// `mogao-calibrate-sim rig` measures, written with 16-bit alpha and the LUT entries as it writes).
// Checks, from outside the process: the status file goes through drift detected / correcting to
// calibrated, the drift it reports falls, the corrected calibration is written back to the MPCDI
// (the previous one kept as .last-good) with the corrected poses in the models file beside it, its
// ground-truth geometric error against the bumped rig is under 1 projector pixel, and it kept the colour: the same
// response LUTs, beta maps, and on the bumped rig's ground-truth light one black and one colour across the seams.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>
#include <thread>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "appliance/autocal/colour_calibration.h"
#include "appliance/autocal/colour_truth.h"
#include "appliance/autocal/model_store.h"
#include "appliance/autocal/rig_bridge.h"
#include "appliance/calibration/mpcdi_screen.h"
#include "appliance/calibration/mpcdi_writer.h"
#include "appliance/rig/rig_file.h"
#include "appliance/selfcal/calibration_store.h"
#include "appliance/selfcal/rig_simulation.h"
#include "common/jpeg_codec.h"
#include "kiosk/config/config_overrides.h"
#include "renderfarm/link/link_test_support.h"
#include "tests/support/child_process.h"

extern char** environ;

namespace mogao {
namespace {

namespace fs = std::filesystem;

constexpr ImageSize kContent{960, 540};

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

Rgb8Image srgb_of(const cv::Mat1f& grey) {
    Rgb8Image out({grey.cols, grey.rows});
    for (int y = 0; y < grey.rows; ++y) {
        for (int x = 0; x < grey.cols; ++x) {
            const double l = std::clamp(static_cast<double>(grey(y, x)), 0.0, 1.0);
            const double e = l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
            std::uint8_t* p = out.at(x, y);
            p[0] = p[1] = p[2] = static_cast<std::uint8_t>(std::lround(e * 255.0));
        }
    }
    return out;
}

double projector_error_px(const rig::VirtualRig& truth, const ScreenCalibration& wall, std::size_t k) {
    rig::VirtualRig one = truth;
    one.projectors = {truth.projectors[k]};
    ScreenCalibration c;
    c.content = wall.content;
    c.projectors = {wall.projectors[k]};
    return autocal::measure_geometry(one, c, 8).mean_px;
}

using mogao::testing::ChildProcess;

TEST(SelfcalKioskEndToEnd, ABumpedProjectorIsCorrectedAndWrittenBackByMogaoKiosk) {
    if (!testing::ipv6_loopback_available()) GTEST_SKIP() << "no IPv6 loopback ([::1]) for the link";
    const testing::TempDir tmp;
    const fs::path dir = tmp.path();
    // The calibration as mogao-calibrate-sim rig leaves it: MPCDI + models beside it.
    const rig::VirtualRig truth =
        autocal::scaled_rig(rig::load_rig(std::string(MOGAO_SOURCE_DIR) + "/rigs/colour.toml"), 0.5, 0.5);
    const selfcal::SystemModel model = selfcal::models_of_rig(truth);
    autocal::AutocalOptions build;
    build.warp_step_px = 4;
    ScreenCalibration wall = autocal::calibration_from_models(model.projectors, model.screen, kContent, build);
    (void)autocal::apply_measured_colour(selfcal::colour_of_rig(truth), model.projectors, model.screen, wall);
    MpcdiExportOptions export_options;
    export_options.alpha_bit_depth = 16;
    export_options.write_response = true;
    write_mpcdi(dir / "screen.mpcdi", to_mpcdi(wall, export_options));
    autocal::write_models(autocal::models_path_for(dir / "screen.mpcdi"),
                          {model.screen, model.camera, model.projectors});
    // The true hardware: proj1 knocked by 1 degree (the full-resolution rig file; the kiosk scales it to the models).
    std::string rig_text = slurp(std::string(MOGAO_SOURCE_DIR) + "/rigs/colour.toml");
    const auto at = rig_text.find("yaw_deg = 0.3");  // proj1, the middle projector
    ASSERT_NE(at, std::string::npos);
    rig_text.replace(at, 13, "yaw_deg = 1.3");
    std::ofstream(dir / "bumped.toml") << rig_text;
    rig::VirtualRig bumped = truth;
    bumped.projectors[1].pose.yaw_deg += 1.0;
    const double before_px = projector_error_px(bumped, selfcal::load_calibration(dir / "screen.mpcdi"), 1);
    ASSERT_GT(before_px, 5.0) << "the bump must be visible in the ground truth";

    // TEST DOUBLE of the farm: the real link server, answering every request with one textured frame.
    const auto& pki = testing::TestPki::get();
    std::ofstream(dir / "ca.pem") << pki.ca.cert_pem;
    std::ofstream(dir / "a.pem") << pki.museum1.cert_pem;
    std::ofstream(dir / "a.key") << pki.museum1.key_pem;
    RenderedFrame content;
    content.size = kContent;
    content.jpeg =
        JpegEncoder().encode(srgb_of(selfcal::make_content(selfcal::ContentKind::textured, 0.0, false, 7)), 95);
    LinkServer farm(testing::test_server_options(), [&content](const ViewRequest&) { return content; });

    const std::string toml = apply_config_overrides(
        kiosk_example_toml(),
        {"farm.endpoint=\"" + farm.endpoint().to_string() + "\"", R"(farm.ca="ca.pem")", R"(farm.cert="a.pem")",
         R"(farm.key="a.key")", "display.rate_hz=10", R"(outputs.backend="headless")", "outputs.composite=false",
         R"(calibration.source="screen.mpcdi")", R"(quality.content="960x540")", "navigation.path_frames=10",
         "stats.file=", R"(stats.status_file="status.json")", "stats.status_period_s=0.2", "selfcal.enabled=true",
         R"(selfcal.camera="rig:bumped.toml")", "selfcal.hold_s=1", "selfcal.transition_s=1"});
    std::ofstream(dir / "kiosk.toml") << toml;
    ChildProcess kiosk({MOGAO_KIOSK_BINARY, "--config", (dir / "kiosk.toml").string(), "--duration-s", "100"});
    ASSERT_TRUE(kiosk.running());

    // Poll the status file (written atomically) until calibrated again after a correction.
    std::set<std::string> states;
    double max_drift = 0.0;
    double last_drift = -1.0;
    nlohmann::json status;
    const auto guard = std::chrono::steady_clock::now() + std::chrono::seconds(90);
    while (std::chrono::steady_clock::now() < guard && !kiosk.exited()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        const std::string text = slurp(dir / "status.json");
        if (text.empty()) continue;
        status = nlohmann::json::parse(text, nullptr, false);
        if (status.is_discarded() || !status["selfcal"].contains("state")) continue;
        if (status["selfcal"]["projectors"].size() < 2) continue;  // before the first monitored frame
        const std::string state = status["selfcal"]["state"];
        states.insert(state);
        const double drift = status["selfcal"]["projectors"][1]["drift_px"];
        max_drift = std::max(max_drift, drift);
        last_drift = drift;
        if (state == "calibrated" && states.count("correcting") > 0 && status["calibration"]["swaps"] > 1) break;
    }
    ASSERT_FALSE(status.is_discarded());
    EXPECT_TRUE(states.count("drift_detected") || states.count("correcting")) << status.dump(2);
    EXPECT_TRUE(states.count("correcting")) << status.dump(2);
    EXPECT_EQ(status["selfcal"]["state"], "calibrated") << status.dump(2);
    EXPECT_GT(status["calibration"]["swaps"].get<int>(), 0) << status.dump(2);
    EXPECT_GT(max_drift, 1.0) << "the monitor saw proj1's drift";
    EXPECT_LT(last_drift, 0.5 * max_drift) << "the drift it reports fell after the correction";
    std::this_thread::sleep_for(std::chrono::milliseconds(500));  // let the store's write finish
    EXPECT_EQ(kiosk.stop(), 0);
    // Written back: the previous calibration kept, the new one right against the bumped rig's ground truth.
    EXPECT_TRUE(fs::exists(selfcal::last_good_path(dir / "screen.mpcdi")));
    // The models beside it hold the corrected pose (a restart monitors the corrected warps with
    // it): proj1's rotation against the bumped rig's true one, the old models kept as .last-good.
    const fs::path models_file = autocal::models_path_for(dir / "screen.mpcdi");
    EXPECT_TRUE(fs::exists(selfcal::last_good_path(models_file)));
    const autocal::CalibrationModels models = autocal::read_models(models_file);
    const selfcal::SystemModel bumped_model = selfcal::models_of_rig(bumped);
    const auto angle_deg = [](const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
        return Eigen::AngleAxisd(a.transpose() * b).angle() * 180.0 / M_PI;
    };
    const double pose_error_deg = angle_deg(models.projectors[1].rotation, bumped_model.projectors[1].rotation);
    EXPECT_LT(pose_error_deg, 0.1) << "was 1 degree before the correction";
    const ScreenCalibration written = selfcal::load_calibration(dir / "screen.mpcdi");
    const double after_px = projector_error_px(bumped, written, 1);
    EXPECT_LT(after_px, 1.0) << "before " << before_px << " px";
    // The colour kept: the projectors' responses unchanged, beta maps re-derived, and the bumped
    // rig's true light showing one black and one grey across the seams.
    ASSERT_EQ(written.projectors.size(), wall.projectors.size());
    for (std::size_t k = 0; k < wall.projectors.size(); ++k) {
        EXPECT_TRUE(written.projectors[k].response.lut == wall.projectors[k].response.lut) << k;
        EXPECT_FALSE(written.projectors[k].beta.rgb.empty()) << k;
    }
    const autocal::SeamColour black = autocal::measure_seam_colour(bumped, written, 0.0);
    const autocal::SeamColour grey = autocal::measure_seam_colour(bumped, written, 0.5);
    EXPECT_LT(black.seam_luminance_p95, 0.02);
    EXPECT_LT(grey.seam_delta_e_p95, 0.6);
    std::cout << "written back: proj1 rotation in the models file " << pose_error_deg
              << " deg from the bumped truth; seam black luminance p95 " << 100.0 * black.seam_luminance_p95
              << " %, seam grey Delta E76 p95 " << grey.seam_delta_e_p95 << "\n";
    std::cout << "proj1 mean geometric error (ground truth, its pixels): " << before_px << " px in the MPCDI before, "
              << after_px << " px in the MPCDI mogao-kiosk wrote; reported drift max " << max_drift << " px, last "
              << last_drift << " px\n";
}

}  // namespace
}  // namespace mogao
