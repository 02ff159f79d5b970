// SPDX-License-Identifier: Apache-2.0
// The views the quality curves are measured on (docs/quality.md): the grotto walk frame as the tour
// renders it (cylindrical screen), a close-up of the textured bali-mask scan, a still view of the
// gilt Buddha and a wide view of the room with its lights (pinhole; the last for the Cycles peer,
// bench/peer), plus the knobs of their converged references.
#pragma once

#include <string>
#include <vector>

#include "common/view_request.h"
#include "renderfarm/scene/scene.h"

namespace mogao::quality {

struct QualityView {
    std::string name;     // file-name-safe id: walk, mask, still, room
    std::string label;    // for tables and plots
    ViewRequest request;  // quality = the farm's defaults (view_request.h); size = the measured size
};

// Reference knobs: enough bounces that truncation is below the reference noise (each bounce keeps at
// most the albedo, <= 0.85 in the grotto), one AO and area sample per sample (more only adds samples;
// these knobs are unbiased), the legacy one-ray-per-light estimator (the default).
inline constexpr int kReferenceBounces = 6;

// width x height of the walk frame (the 16:9 tour frame at reduced resolution); the pinhole views use
// the same width and a 4:3 frame.
[[nodiscard]] std::vector<QualityView> quality_views(const Scene& scene, int width, int height);

// Canonical text of a request's camera, pose, size and quality, for the reference cache key.
[[nodiscard]] std::string describe_request(const ViewRequest& request);

}  // namespace mogao::quality
