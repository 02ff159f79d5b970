// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/lab/synthetic_view.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace mogao {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

cv::Matx33d to_cv(const Eigen::Matrix3d& m) {
    return {m(0, 0), m(0, 1), m(0, 2), m(1, 0), m(1, 1), m(1, 2), m(2, 0), m(2, 1), m(2, 2)};
}

// Homography from the target's cell image (OpenCV convention: cell (u, v) centred on (u, v)) to
// output pixels: cell corner coordinates (u + 0.5, v + 0.5) -> tag plane (x right, y up, centred)
// -> K [r1 r2 t].
cv::Matx33d cells_to_image(const PlanarTarget& t, const TagPose& pose, const CameraIntrinsics& cam) {
    const double s = t.cell_m;
    const cv::Matx33d cells_to_plane(s, 0, (0.5 - t.columns / 2.0) * s, 0, -s, (t.rows / 2.0 - 0.5) * s, 0, 0, 1);
    const Eigen::Matrix3d& r = pose.rotation;
    const Eigen::Vector3d& p = pose.translation_m;
    const cv::Matx33d plane_to_camera(r(0, 0), r(0, 1), p(0), r(1, 0), r(1, 1), p(1), r(2, 0), r(2, 1), p(2));
    const cv::Matx33d k(cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
    return k * plane_to_camera * cells_to_plane;
}

void check_effects(const RenderEffects& e) {
    const auto grey = [](const char* name, double v) {
        if (!(v >= 0.0 && v <= 255.0))
            throw std::invalid_argument(std::string("RenderEffects.") + name + " outside [0, 255]");
    };
    grey("black", e.black);
    grey("white", e.white);
    grey("background", e.background);
    if (!(e.gradient >= 0.0 && e.gradient <= 1.0)) throw std::invalid_argument("RenderEffects.gradient outside [0, 1]");
    if (!(e.motion_blur_px >= 0.0 && e.motion_blur_px <= 100.0)) {
        throw std::invalid_argument("RenderEffects.motion_blur_px outside [0, 100]");
    }
    if (!(e.noise_sigma >= 0.0 && e.noise_sigma <= 100.0))
        throw std::invalid_argument("RenderEffects.noise_sigma outside [0, 100]");
    if (e.supersample < 1 || e.supersample > 16)
        throw std::invalid_argument("RenderEffects.supersample outside [1, 16]");
}

// A normalised line kernel of the given length and direction, anti-aliased.
cv::Mat line_kernel(double length, double angle_deg) {
    const int half = static_cast<int>(std::ceil(length / 2.0)) + 1;
    cv::Mat k = cv::Mat::zeros(2 * half + 1, 2 * half + 1, CV_32F);
    const int steps = std::max(2, static_cast<int>(std::ceil(length * 8.0)));
    const double dx = std::cos(angle_deg * kDeg);
    const double dy = std::sin(angle_deg * kDeg);
    for (int i = 0; i <= steps; ++i) {  // bilinear splat of points along the path
        const double a = (static_cast<double>(i) / steps - 0.5) * length;
        const double x = half + a * dx;
        const double y = half + a * dy;
        const int x0 = static_cast<int>(std::floor(x));
        const int y0 = static_cast<int>(std::floor(y));
        const auto fx = static_cast<float>(x - x0);
        const auto fy = static_cast<float>(y - y0);
        k.at<float>(y0, x0) += (1 - fx) * (1 - fy);
        k.at<float>(y0, x0 + 1) += fx * (1 - fy);
        k.at<float>(y0 + 1, x0) += (1 - fx) * fy;
        k.at<float>(y0 + 1, x0 + 1) += fx * fy;
    }
    return k / cv::sum(k)[0];
}

// A still life around grey `mean`: shapes of random greys, sizes and orientations, then a light
// blur (a camera never resolves perfectly sharp edges in the background either).
cv::Mat clutter(int width, int height, double mean, std::uint64_t seed) {
    cv::Mat img(height, width, CV_32F, cv::Scalar(mean));
    cv::RNG rng(seed);
    const auto grey = [&] { return cv::Scalar(std::clamp(mean + rng.uniform(-90.0, 90.0), 0.0, 255.0)); };
    const int shapes = std::max(20, width * height / 6000);
    for (int i = 0; i < shapes; ++i) {
        const cv::Point2f centre(rng.uniform(0.0f, static_cast<float>(width)),
                                 rng.uniform(0.0f, static_cast<float>(height)));
        switch (i % 4) {
            case 0:
            case 1: {  // rectangles: furniture, frames, books
                const cv::RotatedRect r(centre, cv::Size2f(rng.uniform(8.0f, 160.0f), rng.uniform(8.0f, 160.0f)),
                                        rng.uniform(0.0f, 180.0f));
                cv::Point2f p[4];
                r.points(p);
                const std::vector<cv::Point> poly{p[0], p[1], p[2], p[3]};
                cv::fillConvexPoly(img, poly, grey(), cv::LINE_AA);
                break;
            }
            case 2:
                cv::circle(img, centre, rng.uniform(4, 60), grey(), cv::FILLED, cv::LINE_AA);
                break;
            default:
                cv::line(img, centre, centre + cv::Point2f(rng.uniform(-150.0f, 150.0f), rng.uniform(-150.0f, 150.0f)),
                         grey(), rng.uniform(1, 6), cv::LINE_AA);
        }
    }
    cv::GaussianBlur(img, img, cv::Size(0, 0), 0.8);
    return img;
}

}  // namespace

PlanarTarget tag_target(const TagBitmap& bitmap, double tag_size_m, int card_margin_cells) {
    if (bitmap.cells < 1 || bitmap.border_cells < 1) throw std::invalid_argument("tag_target: empty bitmap");
    if (!(tag_size_m > 0.0)) throw std::invalid_argument("tag_target: tag size must be > 0");
    if (card_margin_cells < 0 || card_margin_cells > 100)
        throw std::invalid_argument("tag_target: card margin outside [0, 100]");
    PlanarTarget t;
    t.columns = t.rows = bitmap.cells + 2 * card_margin_cells;
    t.cell_m = tag_size_m / bitmap.border_cells;
    t.cells.assign(static_cast<std::size_t>(t.columns * t.rows), 255);
    for (int y = 0; y < bitmap.cells; ++y) {
        for (int x = 0; x < bitmap.cells; ++x) {
            t.cells[static_cast<std::size_t>((y + card_margin_cells) * t.columns + x + card_margin_cells)] =
                bitmap.at(x, y);
        }
    }
    return t;
}

PlanarTarget chessboard_target(int inner_columns, int inner_rows, double square_m) {
    if (inner_columns < 2 || inner_rows < 2)
        throw std::invalid_argument("chessboard_target: fewer than 2x2 inner corners");
    PlanarTarget t;
    t.columns = inner_columns + 3;  // inner + 1 squares, plus a white square of margin each side
    t.rows = inner_rows + 3;
    t.cell_m = square_m;
    t.cells.assign(static_cast<std::size_t>(t.columns * t.rows), 255);
    for (int y = 1; y < t.rows - 1; ++y) {
        for (int x = 1; x < t.columns - 1; ++x) {
            if ((x + y) % 2 == 0) t.cells[static_cast<std::size_t>(y * t.columns + x)] = 0;
        }
    }
    return t;
}

namespace {

// The target drawn into `image` over the region its outline covers: each output pixel blends the target's cells
// (supersampled e.supersample times per axis) over what was behind by the pixel's exact coverage.
void composite_target(cv::Mat& image, const PlanarTarget& target, const cv::Matx33d& h,
                      const std::vector<cv::Point2d>& outline, const CameraIntrinsics& camera, const RenderEffects& e) {
    // Region of the output the target covers, with a pixel of margin, clipped to the image.
    double x0 = outline[0].x, x1 = x0, y0 = outline[0].y, y1 = y0;
    for (const auto& p : outline) {
        x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
    }
    // Clip in double first: a target far off-screen must not overflow int.
    const auto clip = [](double v, int hi) {
        return static_cast<int>(std::clamp(v, -1.0, static_cast<double>(hi) + 1.0));
    };
    const int rx0 = clip(std::floor(x0) - 1, camera.width), ry0 = clip(std::floor(y0) - 1, camera.height);
    const int rx1 = clip(std::ceil(x1) + 2, camera.width), ry1 = clip(std::ceil(y1) + 2, camera.height);
    const cv::Rect roi = cv::Rect(rx0, ry0, std::max(0, rx1 - rx0), std::max(0, ry1 - ry0)) &
                         cv::Rect(0, 0, camera.width, camera.height);
    if (roi.area() > 0) {
        // Keep the fine image under ~16 M samples.
        const int s = std::max(1, std::min(e.supersample, static_cast<int>(std::sqrt(16e6 / roi.area()))));
        // Output pixel x (centre at x) covers fine samples s*x .. s*x+s-1 with centres at
        // x - 0.5 + (j + 0.5) / s, so fine = s * (x - roi.x + 0.5) - 0.5.
        const cv::Matx33d to_fine(s, 0, s * (0.5 - roi.x) - 0.5, 0, s, s * (0.5 - roi.y) - 0.5, 0, 0, 1);
        cv::Mat levels(target.rows, target.columns, CV_32F);
        for (int y = 0; y < target.rows; ++y) {
            for (int x = 0; x < target.columns; ++x) {
                const double c = target.cells[static_cast<std::size_t>(y * target.columns + x)] / 255.0;
                levels.at<float>(y, x) = static_cast<float>(e.black + c * (e.white - e.black));
            }
        }
        // Fine samples outside the target are 0 in `fine` and in `cover`; after the box filter,
        // `cover` is each pixel's exact target coverage and `coarse` the target's contribution.
        cv::Mat fine;
        cv::Mat cover;
        cv::warpPerspective(levels, fine, cv::Mat(to_fine * h), cv::Size(roi.width * s, roi.height * s),
                            cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(0));
        cv::warpPerspective(cv::Mat(levels.size(), CV_32F, cv::Scalar(1)), cover, cv::Mat(to_fine * h),
                            cv::Size(roi.width * s, roi.height * s), cv::INTER_NEAREST, cv::BORDER_CONSTANT,
                            cv::Scalar(0));
        cv::Mat coarse;
        cv::Mat coverage;
        cv::resize(fine, coarse, roi.size(), 0, 0, cv::INTER_AREA);
        cv::resize(cover, coverage, roi.size(), 0, 0, cv::INTER_AREA);
        const cv::Mat behind = image(roi);
        const cv::Mat blended = coarse + behind.mul(1.0 - coverage);
        blended.copyTo(image(roi));
    }
}

// The effects after the target: illumination gradient, occluders, motion blur and sensor noise (RenderEffects).
void apply_effects(cv::Mat& image, const CameraIntrinsics& camera, const RenderEffects& e) {
    if (e.gradient > 0.0) {
        for (int x = 0; x < camera.width; ++x) {
            const double g = 1.0 + e.gradient * ((x + 0.5) / camera.width - 0.5);
            image.col(x) *= g;
        }
    }
    for (const Occluder& o : e.occluders) {
        // cv::circle with 4 fractional bits, OpenCV convention (centre - 0.5).
        cv::circle(image,
                   cv::Point(static_cast<int>(std::lround((o.centre_px.x() - 0.5) * 16)),
                             static_cast<int>(std::lround((o.centre_px.y() - 0.5) * 16))),
                   static_cast<int>(std::lround(o.radius_px * 16)), cv::Scalar(o.grey), cv::FILLED, cv::LINE_AA, 4);
    }
    if (e.motion_blur_px > 0.0)
        cv::filter2D(image, image, -1, line_kernel(e.motion_blur_px, e.motion_blur_deg), cv::Point(-1, -1), 0,
                     cv::BORDER_REPLICATE);
    if (e.noise_sigma > 0.0) {
        cv::Mat noise(image.size(), CV_32F);
        cv::RNG rng(e.seed);
        rng.fill(noise, cv::RNG::NORMAL, 0.0, e.noise_sigma);
        image += noise;
    }
}

}  // namespace

GrayImage render_target(const PlanarTarget& target, const TagPose& pose, const CameraIntrinsics& camera,
                        const RenderEffects& e) {
    validate(camera);
    check_effects(e);
    if (target.columns < 1 || target.rows < 1 ||
        target.cells.size() != static_cast<std::size_t>(target.columns * target.rows)) {
        throw std::invalid_argument("render_target: target cells do not match columns x rows");
    }
    const cv::Matx33d h = cells_to_image(target, pose, camera);
    // All four card corners must be in front of the camera, else the homography folds.
    std::vector<cv::Point2d> outline;
    for (const auto& [u, v] : {std::pair{-0.5, -0.5},
                               {target.columns - 0.5, -0.5},
                               {target.columns - 0.5, target.rows - 0.5},
                               {-0.5, target.rows - 0.5}}) {
        const cv::Vec3d q = h * cv::Vec3d(u, v, 1.0);
        if (q[2] <= 1e-9) throw std::invalid_argument("render_target: the target is (partly) behind the camera");
        outline.emplace_back(q[0] / q[2], q[1] / q[2]);
    }
    cv::Mat image = e.clutter_seed != 0 ? clutter(camera.width, camera.height, e.background, e.clutter_seed)
                                        : cv::Mat(camera.height, camera.width, CV_32F, cv::Scalar(e.background));

    composite_target(image, target, h, outline, camera, e);
    apply_effects(image, camera, e);
    cv::Mat out8;
    image.convertTo(out8, CV_8U);  // rounds and saturates
    GrayImage out(camera.width, camera.height);
    for (int y = 0; y < camera.height; ++y) {
        std::copy_n(out8.ptr<std::uint8_t>(y), camera.width,
                    out.pixels.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(camera.width));
    }
    return out;
}

std::array<Eigen::Vector2d, 4> project_tag_corners(const TagPose& pose, const CameraIntrinsics& camera,
                                                   double tag_size_m) {
    validate(camera);
    const double h = tag_size_m / 2.0;
    const std::vector<cv::Point3d> object{{-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}};
    cv::Vec3d rvec;
    cv::Rodrigues(to_cv(pose.rotation), rvec);
    const cv::Vec3d tvec(pose.translation_m.x(), pose.translation_m.y(), pose.translation_m.z());
    const cv::Matx33d k(camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
    std::vector<cv::Point2d> image;
    cv::projectPoints(object, rvec, tvec, k, camera.distortion, image);
    std::array<Eigen::Vector2d, 4> out;
    for (std::size_t i = 0; i < 4; ++i) out[i] = {image[i].x + 0.5, image[i].y + 0.5};  // to AprilTag's convention
    return out;
}

TagPose tag_pose_facing_camera(double distance_m, double yaw_deg, double pitch_deg, double roll_deg, double x_m,
                               double y_m) {
    // Facing the camera: tag x = camera x, tag y = camera -y, tag z = camera -z.
    const Eigen::Matrix3d facing = Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
    // Intrinsic rotations (each about the tag's axes as already turned), signs chosen so that
    // yaw > 0 turns the face normal toward camera +x, pitch > 0 toward camera -y (up), and roll > 0
    // turns the tag's x axis up in the image (counter-clockwise on screen).
    const Eigen::Matrix3d turn = (Eigen::AngleAxisd(yaw_deg * kDeg, Eigen::Vector3d::UnitY()) *
                                  Eigen::AngleAxisd(-pitch_deg * kDeg, Eigen::Vector3d::UnitX()) *
                                  Eigen::AngleAxisd(roll_deg * kDeg, Eigen::Vector3d::UnitZ()))
                                     .toRotationMatrix();
    TagPose pose;
    pose.rotation = facing * turn;
    pose.translation_m = {x_m, y_m, distance_m};
    return pose;
}

CameraIntrinsics ideal_camera(int width, int height, double focal_px) {
    CameraIntrinsics c;
    c.width = width;
    c.height = height;
    c.fx = c.fy = focal_px;
    c.cx = (width - 1) / 2.0;
    c.cy = (height - 1) / 2.0;
    validate(c);
    return c;
}

}  // namespace mogao
