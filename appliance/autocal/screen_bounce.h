// SPDX-License-Identifier: Apache-2.0
// The light a concave screen throws onto itself, as the colour step models it (colour_calibration.h,
// step 0): one bounce between patches of the fitted screen. Pure maths, no camera.
//
// Model: the screen (ScreenModel: cylinder, bow) cut into a grid of patches about `patch_m` square in
// (theta, h). Patch j's light leaving it is matte, L_j (the mean over its area of the light on it);
// patch i receives E_i = rho sum_j F_ij L_j with F_ij = cos_i cos_j A_j / (pi d_ij^2), the form factor
// from a small patch i to patch j (Cohen & Wallace, "Radiosity and Realistic Image Synthesis", 1993,
// ch. 4), cos_i and cos_j between each patch's inward normal and the line joining their centres; every
// pair of points on a cylinder's inside sees the other (no occlusion), F_ii = 0. Between patch centres
// the bounce is interpolated bilinearly in (theta, h), clamped to the outermost centres.
// Units: theta radians, atan2(x, -z) of the screen point (0 at the arc's middle), h metres above the floor
// (screen frame, autocal.h); light in whatever unit L is given in (the bounce comes out in it, per unit rho).
#pragma once

#include <vector>

#include "appliance/autocal/autocal.h"

namespace mogao::autocal {

class ScreenBounce {
public:
    // Throws std::invalid_argument when patch_m is not in [0.01, 1] m or the screen is degenerate.
    explicit ScreenBounce(const ScreenModel& screen, double patch_m = 0.1);

    [[nodiscard]] int columns() const { return columns_; }
    [[nodiscard]] int rows() const { return rows_; }
    [[nodiscard]] int patches() const { return columns_ * rows_; }
    // The patch (theta, h) lies in, or -1 outside the screen.
    [[nodiscard]] int patch_at(double theta, double h) const;
    // sum_j F_ij L_j for every patch i (rho = 1); `leaving` has patches() entries.
    [[nodiscard]] std::vector<double> bounce(const std::vector<double>& leaving) const;
    // F_ij (i receiving from j), row-major patches() x patches().
    [[nodiscard]] const std::vector<double>& form_factors() const { return form_; }
    // A per-patch field (patches() entries) at (theta, h), bilinear between patch centres.
    [[nodiscard]] double at(const std::vector<double>& field, double theta, double h) const;

private:
    int columns_ = 0, rows_ = 0;
    double theta0_ = 0.0, dtheta_ = 0.0, h0_ = 0.0, dh_ = 0.0;
    std::vector<double> form_;  // F_ij, row-major patches() x patches()
};

}  // namespace mogao::autocal
