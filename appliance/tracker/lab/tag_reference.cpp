// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/lab/tag_reference.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <opencv2/aruco.hpp>
#include <opencv2/core.hpp>

#include "appliance/tracker/tag_family.h"

namespace mogao {
namespace {

// Bilinear grey value at (x, y), pixel centres at +0.5; NaN outside the image.
double sample(const GrayImage& image, double x, double y) {
    const double u = x - 0.5;
    const double v = y - 0.5;
    const int x0 = static_cast<int>(std::floor(u));
    const int y0 = static_cast<int>(std::floor(v));
    if (x0 < 0 || y0 < 0 || x0 + 1 >= image.width || y0 + 1 >= image.height)
        return std::numeric_limits<double>::quiet_NaN();
    const double fx = u - x0;
    const double fy = v - y0;
    const double top = (1 - fx) * image.at(x0, y0) + fx * image.at(x0 + 1, y0);
    const double bottom = (1 - fx) * image.at(x0, y0 + 1) + fx * image.at(x0 + 1, y0 + 1);
    return (1 - fy) * top + fy * bottom;
}

struct Line {  // n . p = d, |n| = 1
    Eigen::Vector2d n;
    double d = 0.0;
};

// One edge from a to b; `outward` points from the black square to the white margin.
std::optional<Line> fit_edge(const GrayImage& image, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                             const Eigen::Vector2d& outward, double reach_px) {
    constexpr double kStep = 0.25;
    const double length = (b - a).norm();
    const int samples = std::clamp(static_cast<int>(length), 4, 256);
    std::vector<Eigen::Vector2d> points;
    std::vector<double> weights;
    const int half = static_cast<int>(std::ceil(reach_px / kStep));
    std::vector<double> profile(static_cast<std::size_t>(2 * half + 1));
    for (int k = 0; k < samples; ++k) {
        const double t = 0.12 + 0.76 * (k + 0.5) / samples;
        const Eigen::Vector2d p = a + t * (b - a);
        bool inside = true;
        for (int j = -half; j <= half && inside; ++j) {
            const Eigen::Vector2d q = p + (j * kStep) * outward;
            profile[static_cast<std::size_t>(j + half)] = sample(image, q.x(), q.y());
            inside = !std::isnan(profile[static_cast<std::size_t>(j + half)]);
        }
        if (!inside) continue;
        const double dark = (profile[0] + profile[1]) / 2.0;
        const double bright = (profile[profile.size() - 1] + profile[profile.size() - 2]) / 2.0;
        if (bright - dark < 10.0) continue;  // no edge here (glare, a finger, the image border)
        const double mid = (dark + bright) / 2.0;
        double best = std::numeric_limits<double>::infinity();
        for (std::size_t j = 0; j + 1 < profile.size(); ++j) {
            if ((profile[j] - mid) * (profile[j + 1] - mid) > 0.0 || profile[j] == profile[j + 1]) continue;
            const double s =
                (static_cast<double>(j) + (mid - profile[j]) / (profile[j + 1] - profile[j]) - half) * kStep;
            if (std::abs(s) < std::abs(best)) best = s;
        }
        if (!std::isfinite(best)) continue;
        points.push_back(p + best * outward);
        weights.push_back(bright - dark);
    }
    if (points.size() < 4) return std::nullopt;
    Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
    double total = 0.0;
    for (std::size_t i = 0; i < points.size(); ++i) {
        centroid += weights[i] * points[i];
        total += weights[i];
    }
    centroid /= total;
    Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
    for (std::size_t i = 0; i < points.size(); ++i) {
        const Eigen::Vector2d r = points[i] - centroid;
        scatter += weights[i] * r * r.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(scatter);
    const Eigen::Vector2d normal = eig.eigenvectors().col(0);  // smallest eigenvalue: across the line
    return Line{normal, normal.dot(centroid)};
}

std::optional<Eigen::Vector2d> intersect(const Line& l, const Line& m) {
    Eigen::Matrix2d a;
    a << l.n.transpose(), m.n.transpose();
    if (std::abs(a.determinant()) < 0.05) return std::nullopt;  // within ~3 degrees of parallel
    return a.inverse() * Eigen::Vector2d(l.d, m.d);
}

}  // namespace

std::optional<TagCorners> refine_by_edge_lines(const GrayImage& image, const TagCorners& approx, int border_cells) {
    if (!image.valid()) throw std::invalid_argument("refine_by_edge_lines: invalid image");
    if (border_cells < 3) throw std::invalid_argument("refine_by_edge_lines: border_cells must be >= 3");
    TagCorners corners = approx;
    for (int iteration = 0; iteration < 2; ++iteration) {
        Eigen::Vector2d centre = Eigen::Vector2d::Zero();
        for (const auto& c : corners) centre += c / 4.0;
        std::array<Line, 4> lines;
        for (std::size_t i = 0; i < 4; ++i) {
            const Eigen::Vector2d& a = corners[i];
            const Eigen::Vector2d& b = corners[(i + 1) % 4];
            const Eigen::Vector2d dir = (b - a).normalized();
            Eigen::Vector2d outward(-dir.y(), dir.x());
            if (outward.dot((a + b) / 2.0 - centre) < 0.0) outward = -outward;
            const double cell = (b - a).norm() / border_cells;
            const auto line = fit_edge(image, a, b, outward, std::clamp(0.6 * cell, 1.0, 6.0));
            if (!line) return std::nullopt;
            lines[i] = *line;
        }
        for (std::size_t i = 0; i < 4; ++i) {  // corner i lies on edges i-1 and i
            const auto p = intersect(lines[(i + 3) % 4], lines[i]);
            if (!p) return std::nullopt;
            corners[i] = *p;
        }
    }
    return corners;
}

std::vector<ReferenceTag> reference_tags(const GrayImage& image, const std::string& family) {
    if (!image.valid()) throw std::invalid_argument("reference_tags: invalid image");
    cv::aruco::PREDEFINED_DICTIONARY_NAME name{};
    if (family == "tag36h11") {
        name = cv::aruco::DICT_APRILTAG_36h11;
    } else if (family == "tag36h10") {
        name = cv::aruco::DICT_APRILTAG_36h10;
    } else if (family == "tag25h9") {
        name = cv::aruco::DICT_APRILTAG_25h9;
    } else if (family == "tag16h5") {
        name = cv::aruco::DICT_APRILTAG_16h5;
    } else {
        throw std::invalid_argument("reference_tags: ArUco has no dictionary for family '" + family + "'");
    }
    const auto dictionary = cv::aruco::getPredefinedDictionary(name);
    auto params = cv::aruco::DetectorParameters::create();
    params->cornerRefinementMethod = cv::aruco::CORNER_REFINE_NONE;
    const cv::Mat view(image.height, image.width, CV_8UC1, const_cast<std::uint8_t*>(image.pixels.data()));
    std::vector<std::vector<cv::Point2f>> found;
    std::vector<int> ids;
    cv::aruco::detectMarkers(view, dictionary, found, ids, params);
    const int border = TagFamily(family).border_width_cells();
    std::vector<ReferenceTag> out;
    for (std::size_t k = 0; k < ids.size(); ++k) {
        ReferenceTag tag;
        tag.id = ids[k];
        // ArUco: clockwise from the marker's top-left, pixel centres at 0. Reversed into AprilTag's
        // counter-clockwise order; which corner comes first is matched later (matched_corner_errors).
        for (std::size_t i = 0; i < 4; ++i) {
            const auto& p = found[k][3 - i];
            tag.corners[i] = {p.x + 0.5, p.y + 0.5};
        }
        if (const auto refined = refine_by_edge_lines(image, tag.corners, border)) {
            tag.corners = *refined;
            tag.refined = true;
        }
        out.push_back(tag);
    }
    std::stable_sort(out.begin(), out.end(), [](const ReferenceTag& a, const ReferenceTag& b) { return a.id < b.id; });
    return out;
}

std::array<double, 4> matched_corner_errors(const TagCorners& a, const TagCorners& b) {
    std::array<double, 4> best{};
    double best_sum = std::numeric_limits<double>::infinity();
    for (std::size_t shift = 0; shift < 4; ++shift) {
        std::array<double, 4> e{};
        double sum = 0.0;
        for (std::size_t i = 0; i < 4; ++i) {
            e[i] = (a[i] - b[(i + shift) % 4]).norm();
            sum += e[i];
        }
        if (sum < best_sum) {
            best_sum = sum;
            best = e;
        }
    }
    return best;
}

}  // namespace mogao
