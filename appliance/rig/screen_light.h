// SPDX-License-Identifier: Apache-2.0
// What the screen itself does to the light the projectors throw on it, in the virtual rig: a gain screen's
// lobe (how bright a point looks depends on where it is seen from) and the light a concave screen throws
// back onto itself. Formulas, units and sources in virtual_rig.h's header comment ("Screen gain",
// "Interreflection"); laboratory code, as virtual_rig.h.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "appliance/rig/rig_model.h"
#include "appliance/rig/virtual_rig.h"

namespace mogao::rig {

// G of screen point s lit from `source` and seen from `observer` (screen frame, metres): the factor on a
// matte screen's light, 1 when the screen is matte (gain 1), in (0, gain].
[[nodiscard]] double screen_gain(const RigScreen& screen, ScreenPoint s, const Eigen::Vector3d& source,
                                 const Eigen::Vector3d& observer);

// One bounce of screen-to-screen light on patches about 0.1 m square (at most 4096 of them: a large screen
// gets larger patches), row by row from the top-left (theta = -arc/2, h = top); each patch's form factors to
// every other, computed once.
class ScreenBounce {
public:
    explicit ScreenBounce(const RigScreen& screen);

    [[nodiscard]] int columns() const { return columns_; }
    [[nodiscard]] int rows() const { return rows_; }
    [[nodiscard]] int patches() const { return columns_ * rows_; }
    // Patch i's centre; its corners are centre +- half a patch in theta and h.
    [[nodiscard]] ScreenPoint centre(int i) const;
    [[nodiscard]] double patch_theta_rad() const { return d_theta_; }
    [[nodiscard]] double patch_height_m() const { return d_h_; }

    // The light one bounce adds at each patch's centre: reflectance * sum_j F_ij leaving[j], `leaving` the light
    // leaving each patch (patches() values, the units of the result). Throws std::invalid_argument on a wrong size.
    [[nodiscard]] std::vector<double> bounce(const std::vector<double>& leaving) const;

    // A per-patch field at screen point s, bilinear between patch centres (held at the outermost centres).
    [[nodiscard]] double at(const std::vector<double>& field, ScreenPoint s) const;

private:
    RigScreen screen_;
    int columns_ = 0;
    int rows_ = 0;
    double d_theta_ = 0.0;
    double d_h_ = 0.0;
    std::vector<float> form_factors_;  // patches() x patches(), row i: F_ij
};

}  // namespace mogao::rig
