// SPDX-License-Identifier: Apache-2.0
// The calibration's model trials (autocal.h, AutocalOptions): after the first bundle adjustment, each optional
// model parameter set (the screen's bow, the camera's intrinsics, each projector's lens distortion) is freed in a
// second adjustment and kept only where the fit's cost falls by more than its option's minimum gain on about the
// same correspondences (a model choice by the fall of the maximum-likelihood cost; Hartley & Zisserman, Multiple
// View Geometry, 2nd ed., sec. 4.2 and A6). Internal to mogao_autocal: calibrate() runs them in this order.
#pragma once

#include <vector>

#include "appliance/autocal/autocal.h"
#include "appliance/autocal/bundle_adjust.h"

namespace mogao::autocal::trials {

// AutocalOptions::fit_bow: `ba` is replaced by the bowed fit when kept; `trial` is filled either way.
void try_bow(BundleResult& ba, const std::vector<EdgeObservation>& edges,
             const std::vector<ProjectorObservations>& observations, BundleOptions bo, const AutocalOptions& options,
             BowTrial& trial);

// AutocalOptions::refine_camera_intrinsics: `ba` is replaced when kept; report.intrinsics,
// camera_intrinsics_sigma and condition_number are filled. Throws CalibrationRefused when a kept result
// strays from the prior's intrinsics or is barely determined (the parameter named).
void try_camera_intrinsics(BundleResult& ba, const CalibrationPrior& prior, const std::vector<EdgeObservation>& edges,
                           const std::vector<ProjectorObservations>& observations, BundleOptions bo,
                           const AutocalOptions& options, AutocalReport& report);

// AutocalOptions::fit_projector_distortion: per projector, report.distortion filled; `ba` replaced when any is kept.
void try_projector_distortion(BundleResult& ba, const CalibrationPrior& prior,
                              const std::vector<EdgeObservation>& edges,
                              const std::vector<ProjectorObservations>& observations, BundleOptions bo,
                              const AutocalOptions& options, AutocalReport& report);

// AutocalOptions::check_heights, on told heights only (`bo` as the final adjustment, refine_heights off): `ba` is
// adjusted once more with the top edge free and `check` filled; `ba` itself is left as it is.
void check_told_heights(const BundleResult& ba, const std::vector<EdgeObservation>& edges,
                        const std::vector<ProjectorObservations>& observations, BundleOptions bo,
                        const AutocalOptions& options, HeightsCheck& check);

}  // namespace mogao::autocal::trials
