// SPDX-License-Identifier: Apache-2.0
// The calibrate command's job: MPCDI round trip of the calibration it computes, its report and
// preview, and a refused rig leaving the previous calibration untouched.
#include "appliance/autocal/calibrate_job.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <unistd.h>

#include <gtest/gtest.h>

#include "appliance/autocal/model_store.h"
#include "appliance/autocal/rig_bridge.h"
#include "appliance/calibration/mpcdi_reader.h"
#include "appliance/calibration/mpcdi_screen.h"
#include "appliance/rig/rig_file.h"
#include "common/png_io.h"

namespace mogao::autocal {
namespace {

std::filesystem::path temp_dir(const std::string& name) {
    const auto d =
        std::filesystem::temp_directory_path() / ("mogao-autocal-" + name + "-" + std::to_string(::getpid()));
    std::filesystem::remove_all(d);
    return d;
}

// The columns (across = false) or rows (across = true) of `preview` in which the grid line at `at` (a fraction of
// the frame; lines every 1/16) shows no pixel darker than half the white within 3 pixels: the gaps in the line.
int gaps_in_grid_line(const Rgb8Image& preview, double at, bool across) {
    const int along = across ? preview.size.height : preview.size.width;
    const int extent = across ? preview.size.width : preview.size.height;
    const int centre = static_cast<int>(std::lround(at * extent));
    int white = 0;
    for (int i = 0; i < along; ++i) {
        const int x = across ? extent / 32 : i;  // between two lines
        const int y = across ? i : extent / 32;
        white = std::max(white, int(preview.at(x, y)[1]));
    }
    int gaps = 0;
    for (int i = 4; i < along - 4; ++i) {  // the screen's edges left out
        int darkest = 255;
        for (int d = -3; d <= 3; ++d) {
            const int c = std::clamp(centre + d, 0, extent - 1);
            darkest = std::min(darkest, int(across ? preview.at(c, i)[1] : preview.at(i, c)[1]));
        }
        if (darkest > white / 2) ++gaps;
    }
    return gaps;
}

std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

TEST(CalibrateJob, MpcdiRoundTripGivesTheSameMaps) {
    CalibrateJob job;
    job.rig = std::string(MOGAO_SOURCE_DIR) + "/rigs/standard.toml";
    job.out = temp_dir("roundtrip");
    job.scale = 0.25;
    job.content = {960, 540};
    job.options.warp_step_px = 4;
    const nlohmann::json report = run_calibrate_job(job);
    // The same calibration again (the rig is deterministic), to compare with what the file holds.
    const rig::VirtualRig rig = scaled_rig(rig::load_rig(job.rig), job.scale, job.scale);
    RigPatternSource source(rig);
    AutocalResult direct = calibrate(source, prior_from_rig(rig), job.content, job.options);
    (void)calibrate_colour(source, prior_from_rig(rig).screen, direct.camera, direct.projectors, direct.calibration);
    const ScreenCalibration back = to_screen_calibration(read_mpcdi(job.out / "calibration.mpcdi"));
    ASSERT_EQ(back.projectors.size(), direct.calibration.projectors.size());
    EXPECT_EQ(back.content.width, job.content.width);
    const double alpha_bound = alpha_quantisation_bound(16, 2.2);
    for (std::size_t k = 0; k < back.projectors.size(); ++k) {
        const ProjectorCalibration& a = direct.calibration.projectors[k];
        const ProjectorCalibration& b = back.projectors[k];
        EXPECT_EQ(a.id, b.id);
        ASSERT_EQ(a.warp.uv.size(), b.warp.uv.size());
        ASSERT_EQ(a.blend.weight.size(), b.blend.weight.size());
        double warp_err = 0.0;
        for (std::size_t i = 0; i < a.warp.uv.size(); ++i) {
            ASSERT_EQ(std::isnan(a.warp.uv[i]), std::isnan(b.warp.uv[i])) << "sample " << i;
            if (!std::isnan(a.warp.uv[i])) warp_err = std::max(warp_err, double(std::abs(a.warp.uv[i] - b.warp.uv[i])));
        }
        double blend_err = 0.0;
        for (std::size_t i = 0; i < a.blend.weight.size(); ++i) {
            blend_err = std::max(blend_err, double(std::abs(a.blend.weight[i] - b.blend.weight[i])));
        }
        EXPECT_LE(warp_err, 2e-7) << a.id;  // float rounding of the region-relative positions
        EXPECT_LE(blend_err, alpha_bound) << a.id;
        EXPECT_EQ(a.response.lut, b.response.lut) << a.id;  // ResponseLUT entry: float32, exact
        ASSERT_EQ(a.beta.size, b.beta.size) << a.id;
        ASSERT_EQ(a.beta.rgb.size(), b.beta.rgb.size()) << a.id;
        double beta_err = 0.0;
        double beta_max = 0.0;
        for (std::size_t i = 0; i < a.beta.rgb.size(); ++i) {
            beta_err = std::max(beta_err, double(std::abs(a.beta.rgb[i] - b.beta.rgb[i])));
            beta_max = std::max(beta_max, double(a.beta.rgb[i]));
        }
        EXPECT_LE(beta_err, 0.5 / 65535.0 + 1e-8) << a.id;  // half a 16-bit code
        EXPECT_GT(beta_max, 1e-3) << a.id;                  // black-level compensation present
    }
    // The fitted models beside the MPCDI: the same models as the direct run, matching the MPCDI.
    const CalibrationModels models = read_models(job.out / "calibration.models.json");
    EXPECT_NO_THROW(check_models_match(models, back, "calibration.models.json"));
    ASSERT_EQ(models.projectors.size(), direct.projectors.size());
    for (std::size_t k = 0; k < models.projectors.size(); ++k) {
        EXPECT_NEAR(models.projectors[k].fx_px, direct.projectors[k].fx_px, 1e-9);
        EXPECT_LE((models.projectors[k].position_m - direct.projectors[k].position_m).norm(), 1e-12);
    }
    EXPECT_LE((models.camera.position_m - direct.camera.position_m).norm(), 1e-12);
    EXPECT_EQ(report["projectors"].size(), 3u);
    EXPECT_LE(report["ground_truth"]["geometry_p95_px"].get<double>(), 0.8);
    // The preview's grid lines are continuous across the screen (a line narrower than a preview pixel, sampled at
    // points, broke into dashes).
    const Rgb8Image preview = read_png(job.out / "preview.png");
    for (int line = 4; line <= 12; line += 4) {
        EXPECT_EQ(gaps_in_grid_line(preview, line / 16.0, false), 0) << "horizontal line " << line << "/16";
        EXPECT_EQ(gaps_in_grid_line(preview, line / 16.0, true), 0) << "vertical line " << line << "/16";
    }
    std::filesystem::remove_all(job.out);
}

TEST(CalibrateJob, AutoExposureIsRefusedAndKeepsThePreviousCalibration) {
    CalibrateJob job;
    job.out = temp_dir("auto-exposure");
    std::filesystem::create_directories(job.out);
    std::ofstream(job.out / "calibration.mpcdi") << "last good";
    std::string text = slurp(std::string(MOGAO_SOURCE_DIR) + "/rigs/standard.toml");
    text.replace(text.find("gain = 1.0"), 10, "gain = 1.0\nauto_exposure = true");
    job.rig = job.out / "auto.toml";
    std::ofstream(job.rig) << text;
    job.scale = 0.25;
    job.content = {960, 540};
    try {
        (void)run_calibrate_job(job);
        FAIL() << "calibrated with the camera's auto-exposure on";
    } catch (const CalibrationRefused& e) {
        EXPECT_NE(std::string(e.what()).find("camera auto-exposure is not locked"), std::string::npos) << e.what();
    }
    EXPECT_EQ(slurp(job.out / "calibration.mpcdi"), "last good");
    EXPECT_FALSE(std::filesystem::exists(job.out / "report.json"));
    std::filesystem::remove_all(job.out);
}

TEST(CalibrateJob, RefusedRigLeavesThePreviousCalibration) {
    CalibrateJob job;
    job.out = temp_dir("refused");
    std::filesystem::create_directories(job.out);
    std::ofstream(job.out / "calibration.mpcdi") << "last good";
    // A projector turned away so that only a sliver of it lands on the arc's end.
    std::string text = slurp(std::string(MOGAO_SOURCE_DIR) + "/rigs/standard.toml");
    text.replace(text.find("yaw_deg = -52.0"), 15, "yaw_deg = -120.0");
    job.rig = job.out / "sliver.toml";
    std::ofstream(job.rig) << text;
    job.scale = 0.25;
    job.content = {960, 540};
    try {
        (void)run_calibrate_job(job);
        FAIL() << "calibrated a projector the camera barely sees";
    } catch (const CalibrationRefused& e) {
        EXPECT_NE(std::string(e.what()).find("proj2"), std::string::npos) << e.what();
    }
    EXPECT_EQ(slurp(job.out / "calibration.mpcdi"), "last good");
    EXPECT_FALSE(std::filesystem::exists(job.out / "report.json"));
    std::filesystem::remove_all(job.out);
}

// The predicted seam gate (AutocalOptions::max_predicted_seam): a blend predicted above it is refused
// naming the figure, nothing is written, the last good calibration stays. Every blend has its ramps'
// pixel quantisation (about 2.6 % at quarter scale), so a gate of 1e-4 refuses any.
TEST(CalibrateJob, PredictedSeamAboveItsGateKeepsThePreviousCalibration) {
    CalibrateJob job;
    job.out = temp_dir("seam-gate");
    std::filesystem::create_directories(job.out);
    std::ofstream(job.out / "calibration.mpcdi") << "last good";
    job.rig = std::string(MOGAO_SOURCE_DIR) + "/rigs/standard.toml";
    job.scale = 0.25;
    job.content = {960, 540};
    job.colour = false;
    job.options.phase_shifts = 0;
    job.options.max_predicted_seam = 1e-4;
    try {
        (void)run_calibrate_job(job);
        FAIL() << "calibrated with a predicted seam above its gate";
    } catch (const CalibrationRefused& e) {
        EXPECT_NE(std::string(e.what()).find("predicted seam"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("max_predicted_seam"), std::string::npos) << e.what();
    }
    EXPECT_EQ(slurp(job.out / "calibration.mpcdi"), "last good");
    EXPECT_FALSE(std::filesystem::exists(job.out / "report.json"));
    std::filesystem::remove_all(job.out);
}

// A projector lens measured on the bench (BenchLens, as `mogao-calibrate procam` gives it) in place of the data
// sheet's: on the rig with the projectors' lens distortion and their distortion trial off, the projectors are
// pinholes with the data sheets; with bench lenses (each the rig's own lens off by a bench calibration's errors:
// focal 0.4 %, principal point 2-3 px, k1 0.004) their distortion is held as measured and the geometry's error
// falls (at half scale, colour on: mean 0.143 -> 0.034 px). The report names each projector's prior lens.
TEST(CalibrateJob, ABenchLensReplacesTheDataSheetAndCarriesItsDistortion) {
    CalibrateJob job;
    job.rig = std::string(MOGAO_SOURCE_DIR) + "/rigs/realistic-lens.toml";
    job.out = temp_dir("bench-lens");
    job.scale = 0.25;
    job.content = {960, 540};
    job.colour = false;
    job.options.fit_projector_distortion = false;
    const nlohmann::json data_sheet = run_calibrate_job(job)["ground_truth"];
    const rig::VirtualRig rig = rig::load_rig(job.rig);
    for (const rig::RigProjector& p : rig.projectors) {
        const rig::RigIntrinsics& in = p.intrinsics;
        std::array<double, 5> distortion = in.distortion;
        distortion[0] += 0.004;
        job.bench_lenses.push_back(BenchLens{p.id + ".json", p.resolution, in.fx_px * 1.004, in.fy_px * 1.004,
                                             in.cx_px + 2.0, in.cy_px - 3.0, distortion});
    }
    const nlohmann::json report = run_calibrate_job(job);
    const nlohmann::json& bench = report["ground_truth"];
    // At quarter scale (measured: mean 0.086 -> 0.060 px, p95 0.155 -> 0.098 px).
    EXPECT_LT(bench["geometry_mean_px"].get<double>(), 0.8 * data_sheet["geometry_mean_px"].get<double>());
    EXPECT_LT(bench["geometry_p95_px"].get<double>(), 0.75 * data_sheet["geometry_p95_px"].get<double>());
    EXPECT_EQ(report["projectors"][1]["prior_lens"], rig.projectors[1].id + ".json");
    std::filesystem::remove_all(job.out);
}

}  // namespace
}  // namespace mogao::autocal
