// SPDX-License-Identifier: Apache-2.0
// The camera's own vignetting, measured on site by the colour step (colour_calibration.h, step 1a) from
// the projectors' full-white images, so that the projectors' lens fall-off and the black levels are
// measured in the screen's light and not in the camera's.
//
// Why it is needed: a camera pixel's value is the screen's light there times the camera's vignetting V
// at that pixel. A fall-off fitted to the raw images (a quadratic in the projector's image positions)
// takes the camera's vignetting as the projector's: the correction then brightens the screen toward the
// camera's image corners by 1 / V (up to 25 % for a camera that loses 20 % there), and where two
// projectors overlap, each one's quadratic fits the same V badly at its image's edge, differently, so the
// seam shows the difference. Measured on rigs/realistic-optics.toml (docs/calibration.md, "Colour and
// black level").
//
// Model (both radial about their own lens's principal point, the symmetry of the cos^4 law and of a
// lens's mechanical vignetting): camera V(rho) = 1 - a rho^2 - b rho^4 (the even polynomial of Goldman,
// "Vignette and exposure calibration and compensation", IEEE TPAMI 32(12) 2010, to fourth order), rho =
// distance from the camera's principal point / half its image's diagonal; projector k's fall-off
// 1 - f_k rho_k^2 about its own principal point (the LensFalloff family the colour step keeps, radial).
// The full-white light of projector k at a camera pixel is A_k (1 - f_k rho_k^2) V(rho): the two are
// told apart because the projectors' images lie at different places in the camera's image, so a
// camera-radial V is not a projector-radial fall-off of each. One projector seen at the camera's centre
// does not tell them apart; a Gaussian prior of standard deviation `prior_sigma` on a and b around 0
// (MAP, as the camera intrinsics' prior, autocal.h CameraIntrinsicsSigma) keeps V near 1 there, and the
// fit's covariance gives V's uncertainty at the image's corner (reported).
#pragma once

#include <cstddef>
#include <vector>

#include "appliance/autocal/autocal.h"

namespace mogao::autocal {

struct CameraVignetting {
    double a = 0.0;  // V(rho) = 1 - a rho^2 - b rho^4
    double b = 0.0;
    double corner = 1.0;                    // V at rho = 1 (a corner when the principal point is at the image's centre)
    double corner_sigma = 0.0;              // its standard deviation from the fit's covariance; 0 when not measured
    std::vector<double> projector_falloff;  // f_k of the joint fit (light lost at rho_k = 1), per projector
    int samples = 0;
    double rms = 0.0;  // the fit's residual rms over the samples' mean light (relative)
    bool measured = false;
};

// One camera pixel that one projector lights at full white: its light (camera units, black removed) and
// rho^2 there in the camera (camera_rho2) and in the projector (at the image position the fitted models
// place it, normalised the same way).
struct FlatFieldSample {
    std::size_t projector = 0;
    double light = 0.0;
    double camera_rho2 = 0.0;
    double projector_rho2 = 0.0;
};

// Least squares (Gauss-Newton, with the prior above) of light = A_k (1 - f_k rho_k^2) V(rho) over the
// samples, for A_k, f_k (k < projectors), a and b. Throws std::invalid_argument when a sample names a
// projector >= `projectors`, when `prior_sigma` is not positive, or with fewer than 10 samples.
[[nodiscard]] CameraVignetting fit_camera_vignetting(const std::vector<FlatFieldSample>& samples,
                                                     std::size_t projectors, double prior_sigma);

// rho^2 of image position (x, y) of device d: squared distance from its principal point over its half
// diagonal squared.
[[nodiscard]] double radial_rho2(const DeviceModel& d, double x, double y);

// V at rho^2 (1 when not measured), never below 0.05.
[[nodiscard]] double vignetting_at(const CameraVignetting& v, double rho2);

}  // namespace mogao::autocal
