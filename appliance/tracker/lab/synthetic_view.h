// SPDX-License-Identifier: Apache-2.0
// Synthetic camera images of a planar target (a tag on a white card, or a chessboard) at a known
// pose: the ground truth of the tracker's tests and benchmark (docs/tracking.md, "Measurements").
//
// Rendering: the target is a grid of cells (0 black .. 255 white), centred on the tag frame's
// origin in its plane (tag_pose.h frames). Each output pixel is the area average of the target
// over it: the region around the target is rendered `supersample` times finer with OpenCV
// warpPerspective (nearest cell, so every fine sample is exactly one cell) through the homography
// K [r1 r2 t], then box-filtered down (resize INTER_AREA). Edges are therefore placed to about
// 1/(2 * supersample) px, with no blur of their own. Pinhole only: distortion is not rendered, so
// use intrinsics without distortion. Intrinsics in OpenCV's pixel convention (camera_intrinsics.h);
// every pixel position this header takes or returns has pixel centres at +0.5, like
// TagDetection::corners, so detections and ground truth compare directly.
//
// Background: flat, or (clutter_seed != 0) a seeded still life of overlapping rectangles, discs
// and lines in many greys, lightly blurred -- a room behind the visitor, with edges and corners
// that make the quad search work as hard as on a real frame. The target is composited over it by
// its exact pixel coverage.
//
// Effects, applied in this order: an illumination gradient over the whole image, occluders
// (filled discs), linear motion blur, Gaussian sensor noise, rounding to 8 bits.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "appliance/tracker/camera_intrinsics.h"
#include "appliance/tracker/tag_bitmap.h"
#include "appliance/tracker/tag_pose.h"
#include "drivers/camera/camera_frame.h"

namespace mogao {

struct PlanarTarget {
    int columns = 0;                  // cells per row
    int rows = 0;                     // cells per column
    double cell_m = 0.0;              // side of one cell, metres
    std::vector<std::uint8_t> cells;  // columns * rows, row-major, top row first (as printed)
};

// The tag of `bitmap` with size `tag_size_m` (its corner square), on a white card that extends
// `card_margin_cells` cells beyond the bitmap on every side.
[[nodiscard]] PlanarTarget tag_target(const TagBitmap& bitmap, double tag_size_m, int card_margin_cells = 1);

// A chessboard of (inner_columns + 1) x (inner_rows + 1) squares, top-left square black, on a
// white margin of one square. Its inner corner (c, r) is at tag-frame
// ((c - (inner_columns - 1) / 2) * square, ((inner_rows - 1) / 2 - r) * square, 0).
[[nodiscard]] PlanarTarget chessboard_target(int inner_columns, int inner_rows, double square_m);

struct Occluder {
    Eigen::Vector2d centre_px;  // pixel centres at +0.5
    double radius_px = 0.0;
    double grey = 140.0;  // 0..255
};

struct RenderEffects {
    double black = 30.0;             // grey of a black cell, 0..255
    double white = 220.0;            // grey of a white cell
    double background = 110.0;       // grey around the target (the mean grey of the clutter)
    std::uint64_t clutter_seed = 0;  // 0: flat background; else the seed of a cluttered one
    double gradient = 0.15;          // illumination: x 1 -/+ gradient/2 from the left to the right edge
    std::vector<Occluder> occluders;
    double motion_blur_px = 0.0;   // length of the blur path (0 = none)
    double motion_blur_deg = 0.0;  // its direction, image x toward image y
    double noise_sigma = 0.0;      // Gaussian noise, grey levels
    std::uint64_t seed = 1;        // noise seed: same inputs, same image
    int supersample = 8;           // [1, 16], lowered automatically for targets filling the image
};

// Throws std::invalid_argument for invalid intrinsics, an empty target, a pose with the target
// behind the camera, or effects out of range.
[[nodiscard]] GrayImage render_target(const PlanarTarget& target, const TagPose& pose, const CameraIntrinsics& camera,
                                      const RenderEffects& effects = {});

// The tag's four corners projected with `camera` (incl. its distortion), AprilTag order and pixel
// convention (tag_detector.h): the ground truth for corner errors.
[[nodiscard]] std::array<Eigen::Vector2d, 4> project_tag_corners(const TagPose& pose, const CameraIntrinsics& camera,
                                                                 double tag_size_m);

// A tag at (x_m, y_m, distance_m) in the camera frame, first facing the camera upright, then
// turned by yaw (about its y axis; + turns the face toward the camera's +x), then pitch (about its
// turned x axis; + tilts the face up, toward the camera's -y), then roll (about its z axis;
// + counter-clockwise as the camera sees it). rotation = diag(1,-1,-1) Ry(yaw) Rx(-pitch) Rz(roll).
[[nodiscard]] TagPose tag_pose_facing_camera(double distance_m, double yaw_deg, double pitch_deg = 0.0,
                                             double roll_deg = 0.0, double x_m = 0.0, double y_m = 0.0);

// An ideal camera (no distortion): focal length f px, principal point at the image centre.
[[nodiscard]] CameraIntrinsics ideal_camera(int width = 800, int height = 600, double focal_px = 700.0);

}  // namespace mogao
