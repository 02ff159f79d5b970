// SPDX-License-Identifier: Apache-2.0
// Single-precision forms of camera.h's generate_ray (at pixel centres) and project_to_image, set up
// once per frame for passes that visit every pixel (temporal reprojection: renderfarm/denoise).
// Same image and world conventions as camera.h; pure functions, no Embree.
//
// Both camera models' ray directions are separable at pixel centres: R d = R(column part) + R(row
// part), so a direction is one vector sum and a normalisation (camera.h's formulas regrouped):
//   pinhole   R d_cam    = R (l_x, 0, 0) + R (0, l_y, -1)
//             with l_x = (2 px/W - 1) tan(fov/2) W/H and l_y = (1 - 2 py/H) tan(fov/2);
//   cylinder  R d_screen = R (r sinθ_x, 0, -r cosθ_x) + R ((0, y_y, 0) - eye_m)
// The projection is project_to_image's in float, with the quadratic's positive root taken in the
// form that does not cancel (Press et al., Numerical Recipes 3rd ed., §5.6).
// The cylinder's screen angle is a polynomial atan2 in float (frame_projection.cpp, fast_atan2).
// Accuracy: world positions within tens of metres of the eye land within 1e-3 px of the
// double-precision functions' (frame_projection_test.cpp); the costs are what a pass over a frame
// avoids: per-pixel trigonometry and 3x3 products in double.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "renderfarm/trace/camera.h"

namespace mogao {

// Rays through the pixel centres (x + 0.5, y + 0.5) of `camera`'s render size.
class PixelCentreRays {
public:
    explicit PixelCentreRays(const CameraSetup& camera);
    // Unit world direction of pixel (x, y)'s ray; 0 <= x < W, 0 <= y < H (not checked).
    [[nodiscard]] Eigen::Vector3f direction(int x, int y) const {
        return (columns_[static_cast<std::size_t>(x)] + rows_[static_cast<std::size_t>(y)]).normalized();
    }
    // The world point at `depth` metres along pixel (x, y)'s ray (GuideBuffers::depth's convention).
    [[nodiscard]] Eigen::Vector3f point(int x, int y, float depth) const { return eye_ + depth * direction(x, y); }
    // point() of pixels (0..n-1, y) at depth[0..n-1] into px, py, pz (world metres, one array per axis);
    // n <= W. The same arithmetic a lane at a time, on eight lanes where the CPU has AVX2 (the last
    // bits may differ from point(), which contracts no multiply-add: cpu_level.h).
    void points_row(int y, const float* depth, int n, float* px, float* py, float* pz) const;

private:
    void split_columns();
    Eigen::Vector3f eye_;
    std::vector<Eigen::Vector3f> columns_, rows_;
    std::vector<float> column_x_, column_y_, column_z_;  // columns_ by axis, for points_row
};

// project_to_image of `camera` in float: false where it is false, else the continuous image position.
class FrameProjection {
public:
    explicit FrameProjection(const CameraSetup& camera);
    [[nodiscard]] bool project(const Eigen::Vector3f& p, float& px, float& py) const;
    // project() of the n points (x[i], y[i], z[i]): image position in (px[i], py[i]) and ok[i] = 1
    // where project() is true, else 0 (px, py then unspecified). Branch-free, eight lanes at a time
    // where the CPU has AVX2; within float rounding of project() (frame_projection_test.cpp).
    void project_row(const float* x, const float* y, const float* z, int n, float* px, float* py,
                     std::uint8_t* ok) const;

private:
    bool cylinder_ = false;
    Eigen::Matrix3f to_camera_;  // Rᵀ
    Eigen::Vector3f eye_;
    // Cylinder: the physical eye e (screen frame), c = e_x² + e_z² − r², and the image scales.
    Eigen::Vector3f screen_eye_ = Eigen::Vector3f::Zero();
    float c_ = 0.0f, half_arc_ = 0.0f, px_per_rad_ = 0.0f, top_ = 0.0f, py_per_m_ = 0.0f;
    // Pinhole: px = (q_x / -q_z · sx + 1) W/2, py = (1 − q_y / -q_z · sy) H/2.
    float sx_ = 0.0f, sy_ = 0.0f, half_w_ = 0.0f, half_h_ = 0.0f;
};

}  // namespace mogao
