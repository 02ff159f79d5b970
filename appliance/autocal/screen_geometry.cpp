// SPDX-License-Identifier: Apache-2.0
// Camera pose from the screen's lit edges and projector models from correspondences (autocal.h).
#include "appliance/autocal/screen_geometry.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>

namespace mogao::autocal {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

std::string fmt(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", v);
    return buf;
}

// Sub-pixel crossings of the local half level where the lit mask changes, along columns and rows.
std::vector<EdgeCandidate> find_edges(const cv::Mat1f& lit) {
    std::vector<float> values(lit.begin(), lit.end());
    std::nth_element(values.begin(), values.begin() + static_cast<long>(values.size() * 9 / 10), values.end());
    const float level = 0.5f * values[values.size() * 9 / 10];
    std::vector<EdgeCandidate> out;
    constexpr int kReach = 3;
    const auto scan = [&](int n, int len, bool vertical) {
        for (int i = 0; i < n; ++i) {
            const auto at = [&](int j) { return vertical ? lit(j, i) : lit(i, j); };
            for (int j = kReach + 1; j < len - kReach; ++j) {
                const bool a = at(j - 1) > level;
                const bool b = at(j) > level;
                if (a == b) continue;
                const float in = a ? at(j - 1 - kReach + 1) : at(j + kReach - 1);
                const float out_v = a ? at(j + kReach - 1) : at(j - 1 - kReach + 1);
                if (in - out_v < level) continue;  // weak edge (a shadow, a dim overlap)
                const float half = 0.5f * (in + out_v);
                const float va = at(j - 1);
                const float vb = at(j);
                if ((va - half) * (vb - half) > 0.0f) continue;
                const double t = std::clamp(static_cast<double>((half - va) / (vb - va)), 0.0, 1.0);
                const double pos = (j - 0.5) + t;
                out.push_back({vertical ? cv::Point2d(i + 0.5, pos) : cv::Point2d(pos, i + 0.5), vertical});
            }
        }
    };
    scan(lit.cols, lit.rows, true);
    scan(lit.rows, lit.cols, false);
    return out;
}

Eigen::Matrix3d small_rotation(const Eigen::Vector3d& w) {
    const double a = w.norm();
    return a < 1e-15 ? Eigen::Matrix3d::Identity() : Eigen::AngleAxisd(a, w / a).toRotationMatrix();
}

// Residual of one edge point for pose (R, o): metres on the screen from its edge, or NaN if it
// belongs to no edge within `gate`.
double edge_residual(const ScreenModel& s, const Eigen::Matrix3d& r, const Eigen::Vector3d& o,
                     const Eigen::Vector3d& ray_cam, bool vertical, double gate) {
    const auto hit = cylinder_hit(s, o, r * ray_cam);
    if (!hit) return std::nan("");
    const double theta = std::atan2(hit->x(), -hit->z());
    const double half = s.arc_deg * kDeg / 2.0;
    if (vertical) {
        if (std::abs(theta) > half) return std::nan("");
        const double e =
            std::abs(hit->y() - s.top_m) < std::abs(hit->y() - s.bottom_m) ? hit->y() - s.top_m : hit->y() - s.bottom_m;
        return std::abs(e) < gate ? e : std::nan("");
    }
    if (hit->y() < s.bottom_m || hit->y() > s.top_m) return std::nan("");
    const double e = s.radius_m * (theta > 0.0 ? theta - half : theta + half);
    return std::abs(e) < gate ? e : std::nan("");
}

}  // namespace

std::vector<Eigen::Vector3d> camera_rays(const DeviceModel& camera, const std::vector<cv::Point2d>& image) {
    std::vector<cv::Point2d> distorted(image.size());
    for (std::size_t i = 0; i < image.size(); ++i) {
        distorted[i] = {(image[i].x - camera.cx_px) / camera.fx_px, (image[i].y - camera.cy_px) / camera.fy_px};
    }
    std::vector<cv::Point2d> ideal(image.size());
    if (!image.empty()) {
        cv::undistortPoints(distorted, ideal, cv::Matx33d::eye(), camera.distortion, cv::noArray(), cv::noArray(),
                            cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-14));
    }
    std::vector<Eigen::Vector3d> rays(image.size());
    for (std::size_t i = 0; i < image.size(); ++i) rays[i] = Eigen::Vector3d(ideal[i].x, ideal[i].y, 1.0);
    return rays;
}

namespace {

// The screen's distance from the axis at (theta, h) and its slopes d/dtheta (m/rad) and d/dh (m/m): zero slopes
// outside the screen, where the bow is not (it vanishes on the screen's frame).
struct RadiusAt {
    double r = 0.0;
    double dr_dtheta = 0.0;
    double dr_dh = 0.0;
};

RadiusAt radius_and_slopes(const ScreenModel& screen, double theta, double h) {
    const double arc = screen.arc_deg * std::numbers::pi / 180.0;
    const double height = screen.top_m - screen.bottom_m;
    const auto& a = screen.bow_m;  // index 2 (m - 1) + (n - 1)
    if (std::abs(theta) > arc / 2.0 || h < screen.bottom_m || h > screen.top_m || !(height > 0.0) ||
        (a[0] == 0.0 && a[1] == 0.0 && a[2] == 0.0 && a[3] == 0.0))
        return {screen.radius_m, 0.0, 0.0};
    // sin(2x) = 2 sin(x) cos(x), cos(2x) = cos^2(x) - sin^2(x): one sine and cosine per axis. This runs at every
    // step of every camera ray's intersection with a bowed screen in the bundle adjustment.
    const double u = std::numbers::pi * (theta + arc / 2.0) / arc;
    const double v = std::numbers::pi * (h - screen.bottom_m) / height;
    const double su1 = std::sin(u);
    const double cu1 = std::cos(u);
    const double sv1 = std::sin(v);
    const double cv1 = std::cos(v);
    const double su2 = 2.0 * su1 * cu1;
    const double sv2 = 2.0 * sv1 * cv1;
    const double du2 = 2.0 * (cu1 * cu1 - su1 * su1);  // d sin(2u) / du
    const double dv2 = 2.0 * (cv1 * cv1 - sv1 * sv1);
    const double along_u1 = a[0] * sv1 + a[1] * sv2;
    const double along_u2 = a[2] * sv1 + a[3] * sv2;
    return {screen.radius_m + su1 * along_u1 + su2 * along_u2,
            std::numbers::pi / arc * (cu1 * along_u1 + du2 * along_u2),
            std::numbers::pi / height * (su1 * (a[0] * cv1 + a[1] * dv2) + su2 * (a[2] * cv1 + a[3] * dv2))};
}

}  // namespace

double screen_radius_at(const ScreenModel& screen, double theta, double h) {
    return radius_and_slopes(screen, theta, h).r;
}

namespace {

std::optional<Eigen::Vector3d> hit_radius(double radius, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
    const double a = d.x() * d.x() + d.z() * d.z();
    if (a < 1e-18) return std::nullopt;
    const double b = 2.0 * (o.x() * d.x() + o.z() * d.z());
    const double c = o.x() * o.x() + o.z() * o.z() - radius * radius;
    const double disc = b * b - 4.0 * a * c;
    if (disc < 0.0) return std::nullopt;
    const double t = (-b + std::sqrt(disc)) / (2.0 * a);
    if (t <= 0.0) return std::nullopt;
    return o + t * d;
}

}  // namespace

Eigen::Vector3d screen_position(const ScreenModel& screen, double theta, double h) {
    const double r = screen_radius_at(screen, theta, h);
    return {r * std::sin(theta), h, -r * std::cos(theta)};
}

double screen_gain_at(const ScreenModel& screen, double theta, double h, const Eigen::Vector3d& source,
                      const Eigen::Vector3d& observer) {
    if (screen.gain == 1.0) return 1.0;
    const Eigen::Vector3d x = screen_position(screen, theta, h);
    const Eigen::Vector3d normal(-std::sin(theta), 0.0, std::cos(theta));  // toward the axis
    const Eigen::Vector3d in = (x - source).normalized();
    const Eigen::Vector3d mirrored = in - 2.0 * in.dot(normal) * normal;
    const double alpha = std::acos(std::clamp(mirrored.dot((observer - x).normalized()), -1.0, 1.0));
    const double t = alpha / (screen.half_gain_angle_deg * std::numbers::pi / 180.0);
    return screen.gain * std::exp2(-t * t);
}

std::optional<Eigen::Vector3d> cylinder_hit(const ScreenModel& screen, const Eigen::Vector3d& o,
                                            const Eigen::Vector3d& d) {
    double bow = 0.0;
    for (double a : screen.bow_m) bow += std::abs(a);
    if (bow == 0.0) return hit_radius(screen.radius_m, o, d);
    // g(t) = distance of o + t d from the axis - the screen's radius there: zero on the surface. The
    // surface lies between the cylinders of radius R - sum|a| and R + sum|a|, so the root is bracketed
    // by their hits: g <= 0 at the inner one, >= 0 at the outer, wherever they lie (the radius there is
    // within the bow's excursion of R, on the screen or off it), so neither needs evaluating; a root not
    // found to 1e-12 m is no hit.
    const auto inner = hit_radius(screen.radius_m - bow, o, d);
    const auto outer = hit_radius(screen.radius_m + bow, o, d);
    if (!inner || !outer) return std::nullopt;
    const double nd = d.norm();
    // g(t) and its slope along the ray: d|p|/dt - (dr/dtheta dtheta/dt + dr/dh dh/dt), with |p| the distance from
    // the axis and theta = atan2(x, -z).
    const auto g = [&](double t, double& slope) {
        const Eigen::Vector3d p = o + t * d;
        const double rho2 = p.x() * p.x() + p.z() * p.z();
        const double rho = std::sqrt(rho2);
        const RadiusAt at = radius_and_slopes(screen, std::atan2(p.x(), -p.z()), p.y());
        slope = (p.x() * d.x() + p.z() * d.z()) / rho -
                (at.dr_dtheta * (p.x() * d.z() - p.z() * d.x()) / rho2 + at.dr_dh * d.y());
        return rho - at.r;
    };
    double a = (*inner - o).norm() / nd;
    double b = (*outer - o).norm() / nd;
    // Newton's method from the hit of the cylinder of the mean radius, kept inside the bracket [a, b] that holds
    // the root (a step that would leave it bisects instead): about two evaluations to 1e-12 m, each a sine and
    // cosine per axis and an arc tangent, where the regula falsi from the bracket's ends took about six.
    const auto mean = hit_radius(screen.radius_m, o, d);
    double t = mean ? std::clamp((*mean - o).norm() / nd, a, b) : 0.5 * (a + b);
    for (int i = 0; i < 100; ++i) {
        double slope = 0.0;
        const double gt = g(t, slope);
        if (std::abs(gt) < 1e-12) return o + t * d;
        if (gt <= 0.0) {
            a = t;
        } else {
            b = t;
        }
        const double next = t - gt / slope;
        t = std::isfinite(next) && next > a && next < b ? next : 0.5 * (a + b);
    }
    return std::nullopt;
}

namespace {

// The gates a camera pose from the screen's lit edges must pass; throws CalibrationRefused naming the shortfall.
void check_edge_fit(const EdgeFit& fit, const AutocalOptions& options) {
    if (fit.points < 200) {
        throw CalibrationRefused(
            "camera pose: only " + std::to_string(fit.points) +
            " points on the screen's lit edges (need >= 200): the camera does not see the screen's top and "
            "bottom edges lit (projectors must overfill them)");
    }
    if (fit.side_points < 20) {
        throw CalibrationRefused(
            "camera pose: only " + std::to_string(fit.side_points) +
            " points on the arc's ends (need >= 20): the ends of the screen are not lit or not seen");
    }
    if (fit.rms_m > options.max_edge_rms_m) {
        throw CalibrationRefused("camera pose: edge fit rms " + fmt(fit.rms_m * 1000.0) + " mm above its gate " +
                                 fmt(options.max_edge_rms_m * 1000.0) +
                                 " mm (wrong screen size or camera intrinsics?)");
    }
}

}  // namespace

EdgeFit fit_camera_pose(const cv::Mat1f& lit, const CalibrationPrior& prior, const AutocalOptions& options) {
    const std::vector<EdgeCandidate> edges = find_edges(lit);
    std::vector<cv::Point2d> image;
    for (const EdgeCandidate& e : edges) image.push_back(e.image);
    const std::vector<Eigen::Vector3d> rays = camera_rays(prior.camera, image);
    const Eigen::Matrix3d r0 = prior.camera.rotation;
    const Eigen::Vector3d o0 = prior.camera.position_m;
    Eigen::Matrix<double, 6, 1> p = Eigen::Matrix<double, 6, 1>::Zero();  // position offset, rotation vector
    const auto pose = [&](const Eigen::Matrix<double, 6, 1>& q) {
        return std::make_pair(Eigen::Matrix3d(small_rotation(q.tail<3>()) * r0), Eigen::Vector3d(o0 + q.head<3>()));
    };
    constexpr double kPrior = 1e-3;  // weak pull to the prior pose (m and rad)
    EdgeFit fit;
    for (int iter = 0; iter < 25; ++iter) {
        const double gate = std::max(kEdgeGateM, 0.3 * std::pow(0.75, iter));
        const auto [r, o] = pose(p);
        std::vector<int> used;
        std::vector<double> res;
        for (std::size_t i = 0; i < rays.size(); ++i) {
            const double e = edge_residual(prior.screen, r, o, rays[i], edges[i].vertical_scan, gate);
            if (std::isfinite(e)) {
                used.push_back(static_cast<int>(i));
                res.push_back(e);
            }
        }
        Eigen::Matrix<double, 6, 6> jtj = kPrior * kPrior * Eigen::Matrix<double, 6, 6>::Identity();
        Eigen::Matrix<double, 6, 1> jtr = kPrior * kPrior * p;
        constexpr double kStep = 1e-6;
        for (std::size_t u = 0; u < used.size(); ++u) {
            const int i = used[u];
            Eigen::Matrix<double, 6, 1> row;
            for (int j = 0; j < 6; ++j) {
                Eigen::Matrix<double, 6, 1> q = p;
                q[j] += kStep;
                const auto [rq, oq] = pose(q);
                const double e = edge_residual(prior.screen, rq, oq, rays[static_cast<std::size_t>(i)],
                                               edges[static_cast<std::size_t>(i)].vertical_scan, 1e9);
                row[j] = (e - res[u]) / kStep;
            }
            if (!row.allFinite()) continue;
            jtj += row * row.transpose();
            jtr += row * res[u];
        }
        p -= jtj.ldlt().solve(jtr);
        double ss = 0.0;
        int sides = 0;
        for (std::size_t u = 0; u < used.size(); ++u) {
            ss += res[u] * res[u];
            sides += edges[static_cast<std::size_t>(used[u])].vertical_scan ? 0 : 1;
        }
        fit.points = static_cast<int>(used.size());
        fit.side_points = sides;
        fit.rms_m = used.empty() ? 0.0 : std::sqrt(ss / static_cast<double>(used.size()));
    }
    const auto [r, o] = pose(p);
    fit.camera = prior.camera;
    fit.camera.rotation = r;
    fit.camera.position_m = o;
    fit.candidates = edges;
    fit.edges = select_edges(fit.candidates, fit.camera, prior.screen, kEdgeGateM);
    check_edge_fit(fit, options);
    return fit;
}

std::vector<EdgeObservation> select_edges(const std::vector<EdgeCandidate>& candidates, const DeviceModel& camera,
                                          const ScreenModel& screen, double gate_m) {
    std::vector<cv::Point2d> image;
    for (const EdgeCandidate& c : candidates) image.push_back(c.image);
    const std::vector<Eigen::Vector3d> rays = camera_rays(camera, image);
    std::vector<EdgeObservation> out;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const bool vertical = candidates[i].vertical_scan;
        if (!std::isfinite(edge_residual(screen, camera.rotation, camera.position_m, rays[i], vertical, gate_m))) {
            continue;
        }
        const Eigen::Vector3d x = ray_on_screen(screen, camera, rays[i]);
        ScreenEdge which = std::atan2(x.x(), -x.z()) > 0.0 ? ScreenEdge::right_end : ScreenEdge::left_end;
        if (vertical) {
            which = std::abs(x.y() - screen.top_m) < std::abs(x.y() - screen.bottom_m) ? ScreenEdge::top
                                                                                       : ScreenEdge::bottom;
        }
        out.push_back({rays[i], which, {image[i].x, image[i].y}});
    }
    return out;
}

ProjectorFit fit_projector(const DeviceModel& camera, const CalibrationPrior& prior, int k,
                           const std::vector<cv::Point2d>& camera_points,
                           const std::vector<cv::Point2d>& projector_points, const std::vector<cv::Point2d>& sigmas,
                           const AutocalOptions& options) {
    const DeviceModel& guess = prior.projectors.at(static_cast<std::size_t>(k));
    const std::string who = "projector " + std::to_string(k) + " '" + guess.id + "'";
    const std::vector<Eigen::Vector3d> rays = camera_rays(camera, camera_points);
    std::vector<cv::Point3f> world;
    std::vector<cv::Point2f> proj;
    double angle_sum = 0.0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const Eigen::Vector3d d = (camera.rotation * rays[i]).normalized();
        const auto hit = cylinder_hit(prior.screen, camera.position_m, d);
        if (!hit) continue;
        const Eigen::Vector3d normal = Eigen::Vector3d(-hit->x(), 0.0, -hit->z()).normalized();
        angle_sum += std::acos(std::clamp(-d.dot(normal), -1.0, 1.0)) / kDeg;
        world.emplace_back(static_cast<float>(hit->x()), static_cast<float>(hit->y()), static_cast<float>(hit->z()));
        // OpenCV puts pixel centres at integers.
        proj.emplace_back(static_cast<float>(projector_points[i].x - 0.5),
                          static_cast<float>(projector_points[i].y - 0.5));
    }
    ProjectorFit fit;
    fit.mean_view_angle_deg = world.empty() ? 90.0 : angle_sum / static_cast<double>(world.size());
    if (static_cast<int>(world.size()) < options.min_cells) {
        throw CalibrationRefused(who + ": the camera sees too little of it: " + std::to_string(world.size()) +
                                 " decoded cells (need >= " + std::to_string(options.min_cells) + ")");
    }
    if (fit.mean_view_angle_deg > options.max_view_angle_deg) {
        throw CalibrationRefused(who + ": the camera views its part of the screen at a grazing angle: mean " +
                                 fmt(fit.mean_view_angle_deg) + " deg from the normal (limit " +
                                 fmt(options.max_view_angle_deg) + " deg)");
    }
    // Pose from the data-sheet intrinsics (SQPnP), then Levenberg-Marquardt on focal length,
    // principal point and pose together (bundle_adjust with the camera fixed), dropping
    // correspondences beyond 4x the median residual between rounds.
    cv::Vec3d rv;
    cv::Vec3d tv;
    const cv::Matx33d k0(guess.fx_px, 0, guess.cx_px - 0.5, 0, guess.fy_px, guess.cy_px - 0.5, 0, 0, 1);
    cv::solvePnP(world, proj, k0, cv::noArray(), rv, tv, false, cv::SOLVEPNP_SQPNP);
    cv::Matx33d rm;
    cv::Rodrigues(rv, rm);
    Eigen::Matrix3d r_cs;  // screen -> device
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) r_cs(i, j) = rm(i, j);
    DeviceModel start = guess;
    start.rotation = r_cs.transpose();
    start.position_m = -r_cs.transpose() * Eigen::Vector3d(tv[0], tv[1], tv[2]);
    ProjectorObservations obs;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        if (!cylinder_hit(prior.screen, camera.position_m, camera.rotation * rays[i])) continue;
        obs.rays.push_back(rays[i]);
        obs.projector.emplace_back(projector_points[i].x, projector_points[i].y);
        obs.sigma_px.emplace_back(sigmas[i].x, sigmas[i].y);
        obs.camera_px.emplace_back(camera_points[i].x, camera_points[i].y);
    }
    BundleOptions bo;
    bo.refine_camera = false;
    const BundleResult b = bundle_adjust(prior.screen, camera, {start}, {}, {obs}, bo);
    fit.rms_px = b.rms_px[0];
    fit.rms_sigma = b.rms_sigma[0];
    fit.points = b.inliers[0];
    fit.observations = std::move(obs);
    if (fit.rms_sigma > options.max_projector_rms) {
        throw CalibrationRefused(who + ": fit rms " + fmt(fit.rms_sigma) +
                                 " (in units of the decoded positions' uncertainty, 1 = as good as the decoding) above "
                                 "its gate " +
                                 fmt(options.max_projector_rms) + " (" + fmt(fit.rms_px) +
                                 " px: decoding errors, or the screen is not the cylinder in the prior)");
    }
    fit.model = b.projectors[0];
    return fit;
}

}  // namespace mogao::autocal
