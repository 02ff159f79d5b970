// SPDX-License-Identifier: Apache-2.0
// The bench calibration on real captures (../shared/data/structured-light/procam-kamino410, see its
// PROVENANCE.md): a real 1024x768 projector's Gray code on a 9x7-corner board of 75 mm squares,
// four poses. Accuracy against real data: each pose's decoded projector corners are predicted by a
// calibration made without that pose (leave one capture out). Skipped when the data is absent.
#include <gtest/gtest.h>

#include "appliance/procam/procam_job.h"

namespace mogao::procam {
namespace {

TEST(ProcamReal, FourCapturesCalibrateAndPredictTheHeldOutPose) {
    const std::filesystem::path data = MOGAO_PROCAM_DIR;
    if (!std::filesystem::is_directory(data / "capture_0")) GTEST_SKIP() << data << " is absent (../shared)";
    ProcamJob job;
    job.projector = ImageSize{1024, 768};
    job.board = BoardSpec{9, 7, 75.0};
    for (int i = 0; i < 4; ++i) job.captures.push_back(data / ("capture_" + std::to_string(i)));
    const ProcamJobResult r = run_procam_job(job);
    ASSERT_EQ(r.views.size(), 4u);
    for (const BoardObservation& v : r.views) {
        EXPECT_GT(v.decoded_fraction, 0.3) << v.name;
        EXPECT_EQ(v.board.size(), 63u) << v.name;
    }
    EXPECT_LT(r.calibration.rms, 0.5);
    // The projector's principal point lies in its image (a projector's is often near the bottom edge).
    EXPECT_GT(r.calibration.projector.K(0, 2), 0.0);
    EXPECT_LT(r.calibration.projector.K(0, 2), 1024.0);
    ASSERT_EQ(r.held_out.size(), 4u);
    for (const HeldOutError& h : r.held_out) {
        EXPECT_LE(h.mean_px, 0.5) << h.name;
        EXPECT_LE(h.p95_px, 1.0) << h.name;
    }
}

}  // namespace
}  // namespace mogao::procam
