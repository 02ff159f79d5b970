// SPDX-License-Identifier: Apache-2.0
// FrameIndirectLight: the screen's own light (a concave screen lighting itself) predicted for each content frame and
// handed to the outputs to take off it (appliance/autocal/indirect_light.h for the model, ProjectorRenderer::
// set_indirect_light for what the outputs do with it; docs/calibration.md, "The screen's own light on each frame").
//
// Per frame: the frame's mean linear light over each screen patch (4 x 4 nearest texels per patch, decoded from
// sRGB, fetched where the outputs fetch them: content uv * scale + offset of the late warp's ContentTransform),
// then IndirectLight::field. A late-warp transform that changes without a new frame keeps the field of the last
// frame: it moves the picture by a fraction of a patch, and the field is smooth over patches 0.1 m wide.
//
// Loading (load_frame_indirect_light): the fitted models beside the MPCDI (appliance/autocal/model_store.h) give the
// screen (its measured reflectance for its own light) and the projectors; nothing to take out (nullopt, with a note
// saying why) when there is no models file, its reflectance is below IndirectLight::kMinReflectance, or it does
// not fit the calibration. Errors are notes, never a failure: a frame shown with its indirect light on top is
// still a frame.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "appliance/autocal/indirect_light.h"
#include "common/image.h"
#include "common/projector_calibration.h"
#include "drivers/projector_renderer.h"

namespace mogao {

class FrameIndirectLight {
public:
    explicit FrameIndirectLight(autocal::IndirectLight model) : model_(std::move(model)) {}

    // The field to take off `frame` (sRGB RGB8, rows top first) as the outputs fetch it through `transform`:
    // IndirectLight's columns() x rows(), content units. An empty frame gives an empty field.
    [[nodiscard]] RgbFloatImage field(const Rgb8Image& frame, const ContentTransform& transform) const;
    [[nodiscard]] const autocal::IndirectLight& model() const { return model_; }

private:
    autocal::IndirectLight model_;
};

// The compensation for `screen` from the models file `models` (its MPCDI's, autocal::models_path_for); nullopt with
// `note` set when there is nothing to take out or the file cannot serve (the reason, naming the file).
[[nodiscard]] std::optional<FrameIndirectLight> load_frame_indirect_light(const std::filesystem::path& models,
                                                                          const ScreenCalibration& screen,
                                                                          std::string* note);

}  // namespace mogao
