// SPDX-License-Identifier: Apache-2.0
// A real installation's optics on the virtual rig (rig keys distortion, blur_px, vignetting), each alone on the
// standard rig at half scale: the projectors' lens distortion must be fitted (AutocalOptions::
// fit_projector_distortion, a trial kept per projector where it pays) or the calibration refused, never content
// silently off; defocus and camera vignetting must not be taken for a distortion. Measured against the virtual
// rig's ground truth (rig_bridge.h), never against the calibration's own prediction.
#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "appliance/autocal/autocal.h"
#include "appliance/autocal/rig_bridge.h"
#include "appliance/rig/rig_file.h"

namespace mogao::autocal {
namespace {

rig::VirtualRig standard_half() {
    return scaled_rig(rig::load_rig(std::string(MOGAO_SOURCE_DIR) + "/rigs/standard.toml"), 0.5, 0.5);
}

// The projector lenses of rigs/realistic-lens.toml: barrel, pincushion and barrel, small tangential terms.
constexpr std::array<std::array<double, 5>, 3> kLens{
    {{-0.04, 0.01, 0.0015, -0.001, 0.0}, {0.03, -0.005, -0.001, 0.0008, 0.0}, {-0.02, 0.004, 0.0008, 0.0012, 0.0}}};

struct Outcome {
    bool refused = false;
    GeometryError geometry;
    AutocalReport report;
    std::vector<DeviceModel> projectors;
};

Outcome calibrate_rig(const rig::VirtualRig& rig, bool fit_distortion) {
    RigPatternSource source(rig);
    AutocalOptions o;
    o.fit_projector_distortion = fit_distortion;
    Outcome out;
    try {
        const AutocalResult r = calibrate(source, prior_from_rig(rig), {1920, 1080}, o);
        out.geometry = measure_geometry(rig, r.calibration, 4);
        out.report = r.report;
        out.projectors = r.projectors;
    } catch (const CalibrationRefused& e) {
        std::printf("%s: refused: %s\n", fit_distortion ? "trial" : "pinhole", e.what());
        out.refused = true;
        return out;
    }
    std::printf("%s: geometry mean %.3f p95 %.3f max %.3f px\n", fit_distortion ? "trial" : "pinhole",
                out.geometry.mean_px, out.geometry.p95_px, out.geometry.max_px);
    for (std::size_t k = 0; k < out.report.distortion.size(); ++k) {
        const DistortionTrial& t = out.report.distortion[k];
        std::printf(
            "  projector %zu: distortion trial cost %.4f %s, k1 %.4f k2 %.4f p1 %.5f p2 %.5f (truth %.4f %.4f "
            "%.5f %.5f)\n",
            k, t.relative_cost, t.kept ? "kept" : "not kept", t.distortion[0], t.distortion[1], t.distortion[2],
            t.distortion[3], rig.projectors[k].intrinsics.distortion[0], rig.projectors[k].intrinsics.distortion[1],
            rig.projectors[k].intrinsics.distortion[2], rig.projectors[k].intrinsics.distortion[3]);
    }
    return out;
}

bool meets_goals(const Outcome& o) {
    // The calibration's goals against the rig's ground truth: mean <= 0.3 px, p95 <= 0.8 px.
    return !o.refused && o.geometry.mean_px <= 0.3 && o.geometry.p95_px <= 0.8 &&
           o.geometry.missing + o.geometry.outside < o.geometry.samples / 100;
}

// Lens distortion alone. A pinhole with its focal length and principal point free absorbs most of a few percent
// of k1 (the rigs' lenses, rigs/realistic-lens.toml: 0.187 / 0.381 / 0.915 px mean / p95 / max at half scale as
// a pinhole, 0.170 / 0.247 / 0.673 px with the trial), so the failing case is a stronger lens: k1 of -10 %, +7.5 %,
// -5 % (a short-throw lens's), tangential terms 2.5 times the rigs'.
rig::VirtualRig strong_lens() {
    rig::VirtualRig rig = standard_half();
    for (std::size_t k = 0; k < 3; ++k) {
        rig.projectors[k].intrinsics.distortion = kLens[k];
        for (const std::size_t i : {0, 1, 2, 3}) rig.projectors[k].intrinsics.distortion[i] *= 2.5;
    }
    return rig;
}

// The pinhole calibration (the trial off) of the strong lens is refused or misses the goals (measured: 0.498 /
// 1.028 / 1.613 px, nothing refusing it). About 25 s on 2 idle cores.
TEST(ProjectorLens, PinholeMissesTheGoalsOnAStrongLens) {
    const Outcome pinhole = calibrate_rig(strong_lens(), false);
    EXPECT_TRUE(pinhole.refused || pinhole.geometry.p95_px > 0.8) << pinhole.geometry.p95_px;
    EXPECT_TRUE(pinhole.report.distortion.empty());
}

// With the trial every projector keeps its fitted distortion, k1 within 0.005 of the truth, and the content meets
// the goals (measured: 0.247 / 0.422 / 0.932 px). About 25 s on 2 idle cores.
TEST(ProjectorLens, StrongLensDistortionIsFitted) {
    const rig::VirtualRig rig = strong_lens();
    const Outcome o = calibrate_rig(rig, true);
    ASSERT_FALSE(o.refused);
    EXPECT_TRUE(meets_goals(o)) << o.geometry.mean_px << " / " << o.geometry.p95_px;
    EXPECT_LT(o.geometry.max_px, 1.0);
    ASSERT_EQ(o.report.distortion.size(), 3U);
    for (std::size_t k = 0; k < 3; ++k) {
        EXPECT_TRUE(o.report.distortion[k].kept) << k << ": " << o.report.distortion[k].relative_cost;
        EXPECT_NEAR(o.projectors[k].distortion[0], rig.projectors[k].intrinsics.distortion[0], 0.005) << k;
    }
}

// A pinhole lens: the trial must keep the pinhole (fitting four more coefficients per projector takes up only
// noise) and the standard rig's figures stay those without the trial. Fails on code that always keeps it.
TEST(ProjectorLens, TrialKeepsThePinholeWhereTheLensHasNoDistortion) {
    const rig::VirtualRig rig = standard_half();
    const Outcome o = calibrate_rig(rig, true);
    ASSERT_FALSE(o.refused);
    ASSERT_EQ(o.report.distortion.size(), 3U);
    for (std::size_t k = 0; k < 3; ++k) {
        EXPECT_TRUE(o.report.distortion[k].tried);
        EXPECT_FALSE(o.report.distortion[k].kept) << k << ": " << o.report.distortion[k].relative_cost;
        EXPECT_EQ(o.projectors[k].distortion, (std::array<double, 5>{}));
    }
    EXPECT_TRUE(meets_goals(o)) << o.geometry.mean_px << " / " << o.geometry.p95_px;
}

// Defocus alone (0.7 px Gaussian in the half-scale projectors' pixels, 1.4 px at full resolution) with the
// camera integrating 4 x 4 points per pixel: the decoding still resolves the projectors, the trial does not take
// the blur for a distortion, and the content meets the goals.
TEST(ProjectorLens, DefocusIsNotTakenForADistortion) {
    rig::VirtualRig rig = standard_half();
    for (rig::RigProjector& p : rig.projectors) p.blur_px = 0.7;
    rig.camera.supersample = 4;
    const Outcome o = calibrate_rig(rig, true);
    ASSERT_FALSE(o.refused);
    for (const DistortionTrial& t : o.report.distortion) EXPECT_FALSE(t.kept) << t.relative_cost;
    EXPECT_TRUE(meets_goals(o)) << o.geometry.mean_px << " / " << o.geometry.p95_px;
}

// Camera vignetting alone (20 % of the light lost at the corners): Gray code compares each pattern with its
// inverse and the phase is a ratio, so the geometry is unaffected; the trial keeps the pinholes.
TEST(ProjectorLens, CameraVignettingIsNotTakenForADistortion) {
    rig::VirtualRig rig = standard_half();
    rig.camera.vignetting = 0.2;
    const Outcome o = calibrate_rig(rig, true);
    ASSERT_FALSE(o.refused);
    for (const DistortionTrial& t : o.report.distortion) EXPECT_FALSE(t.kept) << t.relative_cost;
    EXPECT_TRUE(meets_goals(o)) << o.geometry.mean_px << " / " << o.geometry.p95_px;
}

}  // namespace
}  // namespace mogao::autocal
