// SPDX-License-Identifier: Apache-2.0
// Bundle adjustment of the camera pose and the projector models on the cylinder (bundle_adjust.h).
#include "appliance/autocal/bundle_adjust.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <opencv2/core/utility.hpp>

#include "appliance/autocal/screen_geometry.h"

namespace mogao::autocal {
namespace {

constexpr int kCam = 6;   // camera: position offset (3), rotation vector (3)
constexpr int kProj = 9;  // projector: fx, cx, cy, rotation vector (3), position offset (3)
// then, when any projector's distortion is refined, its k1, k2, p1, p2 (every projector's block has them; a
// projector whose distortion stays has those columns held fixed).
constexpr int kProjDistortion = 4;
// Screen (last, when refined): radius offset (m) and arc offset (rad) with refine_screen, the top edge's
// offset (m) with refine_heights, then the four bow amplitudes (m, ScreenModel::bow_m) with refine_bow.
constexpr int kScreenShape = 2;
constexpr int kScreenSpan = 1;
constexpr int kScreenBow = 4;
// Camera intrinsics (last, with refine_camera_intrinsics): fx (fy = fx * the prior's aspect), cx, cy, k1, k2.
constexpr int kIntrinsics = 5;

Eigen::Matrix3d rotation_of(const Eigen::Vector3d& w) {
    const double a = w.norm();
    return a < 1e-15 ? Eigen::Matrix3d::Identity() : Eigen::AngleAxisd(a, w / a).toRotationMatrix();
}

// The camera the parameters describe: pose offsets `q`, and its intrinsics `qi` (nullptr: the prior's).
DeviceModel camera_at(const DeviceModel& c0, const double* q, const double* qi = nullptr) {
    DeviceModel c = c0;
    c.position_m = c0.position_m + Eigen::Vector3d(q[0], q[1], q[2]);
    c.rotation = rotation_of(Eigen::Vector3d(q[3], q[4], q[5])) * c0.rotation;
    if (qi != nullptr) {
        c.fx_px = qi[0];
        c.fy_px = qi[0] * c0.fy_px / c0.fx_px;
        c.cx_px = qi[1];
        c.cy_px = qi[2];
        c.distortion[0] = qi[3];
        c.distortion[1] = qi[4];
    }
    return c;
}

// Normalised undistorted camera ray (z = 1) of image position `p` (pixel centres at +0.5): the
// Brown-Conrady model inverted by OpenCV's fixed-point iteration (undistortPoints), to 1e-14, from
// `start` (a nearby ray, e.g. the same point's for slightly different intrinsics; nullptr: the
// distorted position).
Eigen::Vector3d undistorted_ray(const DeviceModel& c, const Eigen::Vector2d& p,
                                const Eigen::Vector3d* start = nullptr) {
    const double xd = (p.x() - c.cx_px) / c.fx_px;
    const double yd = (p.y() - c.cy_px) / c.fy_px;
    const auto& k = c.distortion;  // k1, k2, p1, p2, k3
    double x = start != nullptr ? start->x() : xd;
    double y = start != nullptr ? start->y() : yd;
    for (int i = 0; i < 100; ++i) {
        const double r2 = x * x + y * y;
        const double radial = 1.0 + r2 * (k[0] + r2 * (k[1] + r2 * k[4]));
        const double dx = 2.0 * k[2] * x * y + k[3] * (r2 + 2.0 * x * x);
        const double dy = k[2] * (r2 + 2.0 * y * y) + 2.0 * k[3] * x * y;
        const double nx = (xd - dx) / radial;
        const double ny = (yd - dy) / radial;
        const bool done = std::abs(nx - x) + std::abs(ny - y) < 1e-14;
        x = nx;
        y = ny;
        if (done) break;
    }
    return {x, y, 1.0};
}

// The projector the parameters describe (`distortion`: q carries its k1, k2, p1, p2 after the pose).
DeviceModel projector_at(const DeviceModel& p0, const double* q, bool distortion = false) {
    DeviceModel p = p0;
    if (distortion) {
        for (int i = 0; i < kProjDistortion; ++i) p.distortion[static_cast<std::size_t>(i)] = q[kProj + i];
    }
    const double aspect = p0.fy_px / p0.fx_px;
    p.fx_px = q[0];
    p.fy_px = q[0] * aspect;
    p.cx_px = q[1];
    p.cy_px = q[2];
    p.rotation = rotation_of(Eigen::Vector3d(q[3], q[4], q[5])) * p0.rotation;
    p.position_m = p0.position_m + Eigen::Vector3d(q[6], q[7], q[8]);
    return p;
}

// The screen the parameters describe: the prior's, with the radius and arc offsets, the top edge and
// the bow when refined.
ScreenModel screen_at(const ScreenModel& s0, const double* qs, bool shape, bool span, bool bow) {
    ScreenModel s = s0;
    if (qs == nullptr) return s;
    if (shape) {
        s.radius_m = s0.radius_m + qs[0];
        s.arc_deg = s0.arc_deg + qs[1] * 180.0 / std::numbers::pi;
        qs += kScreenShape;
    }
    if (span) {
        s.top_m = s0.top_m + qs[0];
        qs += kScreenSpan;
    }
    if (bow) {
        for (std::size_t i = 0; i < s.bow_m.size(); ++i) s.bow_m[i] = s0.bow_m[i] + qs[i];
    }
    return s;
}

using Rays = std::vector<Eigen::Vector3d>;
using Points = std::vector<Eigen::Vector3d>;

// Residuals of one block: the edges (block -1) or projector k's inlier correspondences. `qs` is the
// screen's parameters (nullptr: the prior's screen, fixed); `qi` the camera's intrinsics (nullptr: the
// prior's, fixed). A block's camera rays are computed once per set of camera intrinsics (rays_of).
struct Problem {
    const ScreenModel& screen0;
    const DeviceModel& camera0;
    const std::vector<DeviceModel>& projectors0;
    const std::vector<EdgeObservation>& edges;
    const std::vector<ProjectorObservations>& obs;
    std::vector<std::vector<int>> inliers;  // per projector, indices into obs[k]
    std::vector<char> edge_inlier;          // per edge point: 0 once dropped as an outlier (its residual is then 0)
    std::vector<double> sigma_px;
    double sigma_m = 0.005;
    bool refine_screen = false;
    bool refine_heights = false;
    bool refine_bow = false;
    bool refine_intrinsics = false;
    std::vector<bool> refine_distortion{};  // per projector (empty: none)
    int kp = kProj;                         // parameters per projector block (kProj, + kProjDistortion)
    CameraIntrinsicsSigma camera_sigma{};
    Eigen::Index screen_index = 0;      // first screen parameter in q
    Eigen::Index intrinsics_index = 0;  // first camera intrinsic in q (after the screen's)

    [[nodiscard]] int screen_count() const {
        return (refine_screen ? kScreenShape : 0) + (refine_heights ? kScreenSpan : 0) + (refine_bow ? kScreenBow : 0);
    }
    [[nodiscard]] int parameter_count() const {
        return static_cast<int>(intrinsics_index) + (refine_intrinsics ? kIntrinsics : 0);
    }
    [[nodiscard]] const double* screen_params(const Eigen::VectorXd& q) const {
        return screen_count() > 0 ? q.data() + screen_index : nullptr;
    }
    [[nodiscard]] const double* intrinsic_params(const Eigen::VectorXd& q) const {
        return refine_intrinsics ? q.data() + intrinsics_index : nullptr;
    }
    [[nodiscard]] ScreenModel screen(const double* qs) const {
        return screen_at(screen0, qs, refine_screen, refine_heights, refine_bow);
    }
    // The prior's intrinsics as parameters, and their prior standard deviations.
    [[nodiscard]] Eigen::Matrix<double, kIntrinsics, 1> intrinsics0() const {
        return {camera0.fx_px, camera0.cx_px, camera0.cy_px, camera0.distortion[0], camera0.distortion[1]};
    }
    [[nodiscard]] Eigen::Matrix<double, kIntrinsics, 1> intrinsics_sigma() const {
        const double w = camera0.resolution.width;
        return {camera_sigma.focal * camera0.fx_px, camera_sigma.principal_point * w, camera_sigma.principal_point * w,
                camera_sigma.distortion, camera_sigma.distortion};
    }

    // The camera rays of a block (-1: edges) for camera intrinsics `qi`: from the image positions where
    // the observations carry them (iterated from `start`'s rays when given), else the fixed rays.
    [[nodiscard]] Rays rays_of(int block, const double* qi, const Rays* start = nullptr) const {
        const DeviceModel c = camera_at(camera0, std::array<double, 6>{}.data(), qi);
        const auto from = [&](std::size_t i) { return start != nullptr ? &(*start)[i] : nullptr; };
        Rays out;
        if (block < 0) {
            out.reserve(edges.size());
            for (std::size_t i = 0; i < edges.size(); ++i)
                out.push_back(edges[i].image.allFinite() ? undistorted_ray(c, edges[i].image, from(i)) : edges[i].ray);
            return out;
        }
        const ProjectorObservations& o = obs[static_cast<std::size_t>(block)];
        if (o.camera_px.empty()) return o.rays;
        out.reserve(o.camera_px.size());
        for (std::size_t i = 0; i < o.camera_px.size(); ++i) out.push_back(undistorted_ray(c, o.camera_px[i], from(i)));
        return out;
    }

    [[nodiscard]] Eigen::VectorXd edge_residuals(const double* qc, const double* qs, const Rays& rays) const {
        const ScreenModel screen = this->screen(qs);
        const DeviceModel c = camera_at(camera0, qc);
        const double half = screen.arc_deg * std::numbers::pi / 360.0;
        Eigen::VectorXd r(static_cast<Eigen::Index>(edges.size()));
        for (std::size_t i = 0; i < edges.size(); ++i) {
            const Eigen::Vector3d x = ray_on_screen(screen, c, rays[i]);
            const double theta = std::atan2(x.x(), -x.z());
            double e = 0.0;
            switch (edges[i].edge) {
                case ScreenEdge::top:
                    e = x.y() - screen.top_m;
                    break;
                case ScreenEdge::bottom:
                    e = x.y() - screen.bottom_m;
                    break;
                case ScreenEdge::left_end:
                    e = screen.radius_m * (theta + half);
                    break;
                case ScreenEdge::right_end:
                    e = screen.radius_m * (theta - half);
                    break;
            }
            r[static_cast<Eigen::Index>(i)] = std::isfinite(e) && edge_inlier[i] != 0 ? e / sigma_m : 0.0;
        }
        return r;
    }

    // Projector k's inlier points on the screen: its camera rays' hits for camera pose qc and screen qs.
    [[nodiscard]] Points projector_points(std::size_t k, const double* qc, const double* qs, const Rays& rays) const {
        const ScreenModel screen = this->screen(qs);
        const DeviceModel c = camera_at(camera0, qc);
        const std::vector<int>& use = inliers[k];
        Points x(use.size());
        for (std::size_t u = 0; u < use.size(); ++u)
            x[u] = ray_on_screen(screen, c, rays[static_cast<std::size_t>(use[u])]);
        return x;
    }

    // Projector k's residuals for its parameters qp, from its inlier points (projector_points).
    [[nodiscard]] Eigen::VectorXd projector_residuals(std::size_t k, const double* qp, const Points& x) const {
        const DeviceModel p = projector_at(projectors0[k], qp, kp > kProj);
        const Eigen::Matrix3d rt = p.rotation.transpose();
        const std::vector<int>& use = inliers[k];
        Eigen::VectorXd r(2 * static_cast<Eigen::Index>(use.size()));
        for (std::size_t u = 0; u < use.size(); ++u) {
            const auto i = static_cast<std::size_t>(use[u]);
            const Eigen::Vector3d d = rt * (x[u] - p.position_m);
            Eigen::Vector2d e(1e3, 1e3);  // behind the projector or missed: a large, constant residual
            if (d.allFinite() && d.z() > 1e-9) {
                const Eigen::Vector2d image = device_image(p, d);
                if (image.allFinite()) e = image - obs[k].projector[i];
            }
            if (!obs[k].sigma_px.empty()) e = e.cwiseQuotient(obs[k].sigma_px[i]);
            r.segment<2>(2 * static_cast<Eigen::Index>(u)) = e / sigma_px[k];
        }
        return r;
    }

    [[nodiscard]] const double* projector_params(const Eigen::VectorXd& v, int block) const {
        return v.data() + kCam + kp * block;
    }

    // Residuals of block (-1: edges) at parameters v, with the block's rays for v's camera intrinsics.
    [[nodiscard]] Eigen::VectorXd block_residuals(int block, const Eigen::VectorXd& v, const Rays& rays) const {
        if (block < 0) return edge_residuals(v.data(), screen_params(v), rays);
        const auto k = static_cast<std::size_t>(block);
        return projector_residuals(k, projector_params(v, block),
                                   projector_points(k, v.data(), screen_params(v), rays));
    }
};

// Forward-difference step of parameter `idx` of q: pixels for intrinsics (1e-4), metres and radians for
// poses and the screen (1e-8), distortion coefficients (1e-7).
double step_of(const Problem& pb, int idx) {
    if (idx < kCam) return 1e-8;
    if (idx >= pb.intrinsics_index) return idx - pb.intrinsics_index < 3 ? 1e-4 : 1e-7;
    if (idx >= pb.screen_index) return 1e-8;
    const int j = (idx - kCam) % pb.kp;
    return j < 3 ? 1e-4 : (j < kProj ? 1e-8 : 1e-7);
}

// Adds block's J^T J and J^T r (columns: the camera's, if refined, the block's own, the screen's and
// the camera intrinsics', if refined) to the system.
void accumulate(const Problem& pb, const Eigen::VectorXd& q, int block, bool refine_camera, Eigen::MatrixXd& jtj,
                Eigen::VectorXd& jtr, double& cost) {
    const Rays rays = pb.rays_of(block, pb.intrinsic_params(q));
    // A projector's own parameters move only its projection, not the points on the screen: their columns reuse the
    // points at q (the same numbers, without the screen intersections that are most of the adjustment's time).
    const Points points =
        block >= 0 ? pb.projector_points(static_cast<std::size_t>(block), q.data(), pb.screen_params(q), rays)
                   : Points{};
    const Eigen::VectorXd r0 =
        block >= 0 ? pb.projector_residuals(static_cast<std::size_t>(block), pb.projector_params(q, block), points)
                   : pb.block_residuals(block, q, rays);
    cost += r0.squaredNorm();
    std::vector<int> cols;
    if (refine_camera) {
        for (int j = 0; j < kCam; ++j) cols.push_back(j);
    }
    if (block >= 0) {
        const bool free = pb.kp > kProj && pb.refine_distortion[static_cast<std::size_t>(block)];
        for (int j = 0; j < (free ? pb.kp : kProj); ++j) cols.push_back(kCam + pb.kp * block + j);
    }
    for (int j = 0; j < pb.screen_count(); ++j) cols.push_back(static_cast<int>(pb.screen_index) + j);
    for (int j = 0; j < (pb.refine_intrinsics ? kIntrinsics : 0); ++j)
        cols.push_back(static_cast<int>(pb.intrinsics_index) + j);
    const Eigen::Index own_begin = kCam + pb.kp * static_cast<Eigen::Index>(block);
    Eigen::MatrixXd jac(r0.size(), static_cast<Eigen::Index>(cols.size()));
    // Each column is a forward difference over the whole block, independent of the others: they run in parallel
    // (OpenCV's pool, every core), each written to its own column, so the result does not depend on the threads.
    cv::parallel_for_(cv::Range(0, static_cast<int>(cols.size())), [&](const cv::Range& range) {
        for (int c = range.start; c < range.end; ++c) {
            Eigen::VectorXd v = q;
            const int idx = cols[static_cast<std::size_t>(c)];
            const double h = step_of(pb, idx);
            v[idx] += h;
            Eigen::VectorXd r;
            if (block >= 0 && idx >= own_begin && idx < own_begin + pb.kp)
                r = pb.projector_residuals(static_cast<std::size_t>(block), pb.projector_params(v, block), points);
            else if (idx >= pb.intrinsics_index)
                r = pb.block_residuals(block, v, pb.rays_of(block, pb.intrinsic_params(v), &rays));
            else r = pb.block_residuals(block, v, rays);
            jac.col(c) = (r - r0) / h;
        }
    });
    const Eigen::MatrixXd a = jac.transpose() * jac;
    const Eigen::VectorXd b = jac.transpose() * r0;
    for (std::size_t i = 0; i < cols.size(); ++i) {
        jtr[cols[i]] += b[static_cast<Eigen::Index>(i)];
        for (std::size_t j = 0; j < cols.size(); ++j) {
            jtj(cols[i], cols[j]) += a(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
        }
    }
}

// The prior on the camera's intrinsics: residuals (q_i - prior_i) / sigma_i.
Eigen::Matrix<double, kIntrinsics, 1> intrinsics_prior_residuals(const Problem& pb, const Eigen::VectorXd& q) {
    if (!pb.refine_intrinsics) return Eigen::Matrix<double, kIntrinsics, 1>::Zero();
    return (q.segment<kIntrinsics>(pb.intrinsics_index) - pb.intrinsics0()).cwiseQuotient(pb.intrinsics_sigma());
}

// The whole system's normal equations at q (every block, the intrinsics' prior); returns the cost.
double normal_equations(const Problem& pb, const Eigen::VectorXd& q, bool refine_camera, Eigen::MatrixXd& jtj,
                        Eigen::VectorXd& jtr) {
    jtj = Eigen::MatrixXd::Zero(q.size(), q.size());
    jtr = Eigen::VectorXd::Zero(q.size());
    double cost = 0.0;
    const int blocks = static_cast<int>(pb.obs.size());
    for (int b = refine_camera ? -1 : 0; b < blocks; ++b) accumulate(pb, q, b, refine_camera, jtj, jtr, cost);
    if (pb.refine_intrinsics) {
        const Eigen::Matrix<double, kIntrinsics, 1> r = intrinsics_prior_residuals(pb, q);
        const Eigen::Matrix<double, kIntrinsics, 1> inv = pb.intrinsics_sigma().cwiseInverse();
        const Eigen::Index i0 = pb.intrinsics_index;
        for (int j = 0; j < kIntrinsics; ++j) {
            jtj(i0 + j, i0 + j) += inv[j] * inv[j];
            jtr[i0 + j] += inv[j] * r[j];
        }
        cost += r.squaredNorm();
    }
    if (!refine_camera) jtj.topLeftCorner<kCam, kCam>().setIdentity();  // fixed: zero step
    for (std::size_t k = 0; pb.kp > kProj && k < pb.refine_distortion.size(); ++k) {
        if (pb.refine_distortion[k]) continue;
        for (int j = kProj; j < pb.kp; ++j) {  // a projector whose distortion stays: zero step
            const Eigen::Index i = kCam + pb.kp * static_cast<Eigen::Index>(k) + j;
            jtj(i, i) = 1.0;
            jtr[i] = 0.0;
        }
    }
    return cost;
}

double total_cost(const Problem& pb, const Eigen::VectorXd& q, bool refine_camera) {
    const double* qi = pb.intrinsic_params(q);
    // Block b + 1's cost (b = -1: the edges), in parallel, then summed in block order as one loop would.
    std::vector<double> costs(pb.obs.size() + 1, 0.0);
    cv::parallel_for_(cv::Range(refine_camera ? -1 : 0, static_cast<int>(pb.obs.size())), [&](const cv::Range& range) {
        for (int b = range.start; b < range.end; ++b)
            costs[static_cast<std::size_t>(b + 1)] = pb.block_residuals(b, q, pb.rays_of(b, qi)).squaredNorm();
    });
    double cost = 0.0;
    for (const double c : costs) cost += c;
    return cost + intrinsics_prior_residuals(pb, q).squaredNorm();
}

void levenberg_marquardt(const Problem& pb, Eigen::VectorXd& q, bool refine_camera, int max_iterations) {
    double lambda = 1e-3;
    for (int iter = 0; iter < max_iterations; ++iter) {
        Eigen::MatrixXd jtj;
        Eigen::VectorXd jtr;
        const double cost = normal_equations(pb, q, refine_camera, jtj, jtr);
        bool improved = false;
        for (int tries = 0; tries < 8 && !improved; ++tries) {
            Eigen::MatrixXd a = jtj;
            a.diagonal() += lambda * jtj.diagonal().cwiseMax(1e-12);
            const Eigen::VectorXd next = q - a.ldlt().solve(jtr);
            const double c = total_cost(pb, next, refine_camera);
            if (std::isfinite(c) && c < cost) {
                improved = true;
                q = next;
                lambda = std::max(lambda / 10.0, 1e-9);
                if (cost - c < 1e-10 * cost) return;
            } else {
                lambda *= 10.0;
            }
        }
        if (!improved) return;
    }
}

// Re-weights projector k from its current residuals (sigma = rms) and drops its outliers (> 4x the
// median; none in the last round), recording the rms in `out`.
void reweight(Problem& pb, const Eigen::VectorXd& q, std::size_t k, bool last, BundleResult& out) {
    const double old_sigma = pb.sigma_px[k];
    const int b = static_cast<int>(k);
    const Eigen::VectorXd r = pb.block_residuals(b, q, pb.rays_of(b, pb.intrinsic_params(q))) * old_sigma;
    std::vector<double> err(pb.inliers[k].size());
    for (std::size_t u = 0; u < err.size(); ++u) err[u] = r.segment<2>(2 * static_cast<Eigen::Index>(u)).norm();
    std::vector<double> sorted = err;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
    const double limit = 4.0 * std::max(sorted[sorted.size() / 2], 0.01);
    std::vector<int> keep;
    double ss = 0.0;
    double ss_px = 0.0;
    for (std::size_t u = 0; u < err.size(); ++u) {
        if (last || err[u] <= limit) {
            const auto i = static_cast<std::size_t>(pb.inliers[k][u]);
            const Eigen::Vector2d s = pb.obs[k].sigma_px.empty() ? Eigen::Vector2d(1.0, 1.0) : pb.obs[k].sigma_px[i];
            keep.push_back(pb.inliers[k][u]);
            ss += err[u] * err[u];
            ss_px += r.segment<2>(2 * static_cast<Eigen::Index>(u)).cwiseProduct(s).squaredNorm();
        }
    }
    const double count = std::max<double>(1.0, static_cast<double>(keep.size()));
    out.rms_sigma[k] = std::sqrt(ss / count);
    out.rms_px[k] = std::sqrt(ss_px / count);
    out.inliers[k] = static_cast<int>(keep.size());
    pb.inliers[k] = std::move(keep);
    pb.sigma_px[k] = std::max(out.rms_sigma[k], 1e-3);
}

// Re-weights the edges from their current residuals (sigma_m = the inliers' rms) and, unless `keep_all`, drops their
// outliers (beyond 4x the median distance), as reweight does a projector's correspondences. An edge point
// can lie off the screen's edge yet within the assignment's gate (select_edges). Measured on realistic-install with
// the screen fitted: without the rule its geometry error is larger, also with the lit edges found one projector at
// a time (autocal::lit_screen, which removed the overlaps' saturated crossings that first called for it).
void reweight_edges(Problem& pb, const Eigen::VectorXd& q, bool keep_all, BundleResult& out) {
    const Eigen::VectorXd r =
        pb.edge_residuals(q.data(), pb.screen_params(q), pb.rays_of(-1, pb.intrinsic_params(q))) * pb.sigma_m;
    const auto at = [&](std::size_t i) { return std::abs(r[static_cast<Eigen::Index>(i)]); };
    std::vector<double> err;
    for (std::size_t i = 0; i < pb.edges.size(); ++i) {
        if (pb.edge_inlier[i] != 0) err.push_back(at(i));
    }
    if (!keep_all && !err.empty()) {
        std::nth_element(err.begin(), err.begin() + static_cast<long>(err.size() / 2), err.end());
        const double limit = 4.0 * std::max(err[err.size() / 2], 1e-5);
        for (std::size_t i = 0; i < pb.edges.size(); ++i) {
            if (at(i) > limit) pb.edge_inlier[i] = 0;
        }
    }
    double ss = 0.0;
    int kept = 0;
    for (std::size_t i = 0; i < pb.edges.size(); ++i) {
        if (pb.edge_inlier[i] == 0) continue;
        ss += at(i) * at(i);
        ++kept;
    }
    out.edge_rms_m = std::sqrt(ss / std::max(kept, 1));
    out.edge_inliers = kept;
    pb.sigma_m = std::max(out.edge_rms_m, 1e-5);
}

// BundleResult's conditioning figures from the normal matrix at the solution.
void conditioning(const Problem& pb, const Eigen::VectorXd& q, bool refine_camera, BundleResult& out) {
    Eigen::MatrixXd n;
    Eigen::VectorXd g;
    (void)normal_equations(pb, q, refine_camera, n, g);
    const Eigen::VectorXd d = n.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
    const Eigen::MatrixXd scaled = d.asDiagonal() * n * d.asDiagonal();
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(scaled, Eigen::EigenvaluesOnly);
    const Eigen::VectorXd ev = eig.eigenvalues();
    out.condition_number =
        ev.minCoeff() > 0.0 ? ev.maxCoeff() / ev.minCoeff() : std::numeric_limits<double>::infinity();
    if (!pb.refine_intrinsics) return;
    const Eigen::MatrixXd cov =
        d.asDiagonal() * scaled.ldlt().solve(Eigen::MatrixXd::Identity(n.rows(), n.cols())) * d.asDiagonal();
    for (int j = 0; j < kIntrinsics; ++j)
        out.camera_intrinsics_sigma.push_back(
            std::sqrt(std::max(0.0, cov(pb.intrinsics_index + j, pb.intrinsics_index + j))));
}

}  // namespace

Eigen::Vector2d device_image(const DeviceModel& d, const Eigen::Vector3d& q) {
    const auto& k = d.distortion;
    if (k == std::array<double, 5>{}) return {d.fx_px * q.x() / q.z() + d.cx_px, d.fy_px * q.y() / q.z() + d.cy_px};
    const double x = q.x() / q.z();
    const double y = q.y() / q.z();
    double corner2 = 0.0;
    for (const double cx : {0.0, static_cast<double>(d.resolution.width)}) {
        for (const double cy : {0.0, static_cast<double>(d.resolution.height)}) {
            corner2 = std::max(corner2, std::pow((cx - d.cx_px) / d.fx_px, 2) + std::pow((cy - d.cy_px) / d.fy_px, 2));
        }
    }
    const double r2 = x * x + y * y;
    if (!(r2 <= 4.0 * corner2)) return {std::nan(""), std::nan("")};
    const double radial = 1.0 + r2 * (k[0] + r2 * (k[1] + r2 * k[4]));
    const double xd = x * radial + 2.0 * k[2] * x * y + k[3] * (r2 + 2.0 * x * x);
    const double yd = y * radial + k[2] * (r2 + 2.0 * y * y) + 2.0 * k[3] * x * y;
    return {d.fx_px * xd + d.cx_px, d.fy_px * yd + d.cy_px};
}

Eigen::Vector3d device_ray(const DeviceModel& d, double x, double y) {
    if (d.distortion == std::array<double, 5>{}) return {(x - d.cx_px) / d.fx_px, (y - d.cy_px) / d.fy_px, 1.0};
    return undistorted_ray(d, Eigen::Vector2d(x, y));
}

Eigen::Vector3d ray_on_screen(const ScreenModel& screen, const DeviceModel& camera, const Eigen::Vector3d& ray) {
    const auto hit = cylinder_hit(screen, camera.position_m, camera.rotation * ray);
    return hit ? *hit : Eigen::Vector3d::Constant(std::nan(""));
}

BundleResult bundle_adjust(const ScreenModel& screen, const DeviceModel& camera,
                           const std::vector<DeviceModel>& projectors, const std::vector<EdgeObservation>& edges,
                           const std::vector<ProjectorObservations>& observations, const BundleOptions& options) {
    if (projectors.size() != observations.size()) {
        throw std::invalid_argument("bundle_adjust: " + std::to_string(projectors.size()) + " projectors but " +
                                    std::to_string(observations.size()) + " observation sets");
    }
    const std::size_t n = projectors.size();
    Problem pb{screen, camera, projectors, edges, observations, {}, {}, std::vector<double>(n, 1.0), 0.005};
    const bool refine_camera = options.refine_camera && !edges.empty();
    // The screen needs the edges (its ends and heights) and the camera refined with it; so do the camera's
    // intrinsics (the edges tie its focal length to the screen's known size).
    pb.refine_screen = options.refine_screen && refine_camera;
    pb.refine_heights = options.refine_heights && !pb.refine_screen && refine_camera;
    pb.refine_bow = options.refine_bow && refine_camera;
    pb.refine_intrinsics = options.refine_camera_intrinsics && refine_camera;
    pb.camera_sigma = options.camera_sigma;
    pb.edge_inlier.assign(edges.size(), 1);
    pb.refine_distortion = options.refine_projector_distortion;
    pb.refine_distortion.resize(n, false);
    if (std::find(pb.refine_distortion.begin(), pb.refine_distortion.end(), true) != pb.refine_distortion.end())
        pb.kp = kProj + kProjDistortion;
    pb.screen_index = kCam + pb.kp * static_cast<Eigen::Index>(n);
    pb.intrinsics_index = pb.screen_index + pb.screen_count();
    Eigen::VectorXd q = Eigen::VectorXd::Zero(pb.parameter_count());
    for (std::size_t k = 0; k < n; ++k) {
        const ProjectorObservations& o = observations[k];
        if (o.rays.size() != o.projector.size() || o.rays.size() < 10 ||
            (!o.camera_px.empty() && o.camera_px.size() != o.rays.size())) {
            throw std::invalid_argument("bundle_adjust: projector " + std::to_string(k) +
                                        ": needs >= 10 correspondences with as many rays (and camera positions, if "
                                        "any) as projector positions");
        }
        if (pb.refine_intrinsics && o.camera_px.empty()) {
            throw std::invalid_argument("bundle_adjust: projector " + std::to_string(k) +
                                        ": refining the camera's intrinsics needs its camera positions (camera_px)");
        }
        pb.inliers.emplace_back(o.rays.size());
        for (std::size_t i = 0; i < o.rays.size(); ++i) pb.inliers[k][i] = static_cast<int>(i);
        const auto base = static_cast<Eigen::Index>(kCam + pb.kp * static_cast<int>(k));
        q[base] = projectors[k].fx_px;
        q[base + 1] = projectors[k].cx_px;
        q[base + 2] = projectors[k].cy_px;
        for (int j = kProj; j < pb.kp; ++j) q[base + j] = projectors[k].distortion[static_cast<std::size_t>(j - kProj)];
    }
    if (pb.refine_intrinsics) q.segment<kIntrinsics>(pb.intrinsics_index) = pb.intrinsics0();
    BundleResult out;
    out.rms_px.assign(n, 0.0);
    out.rms_sigma.assign(n, 0.0);
    out.inliers.assign(n, 0);
    for (int round = 0; round <= options.rounds; ++round) {
        for (std::size_t k = 0; k < n; ++k) reweight(pb, q, k, round == options.rounds, out);
        // Edge outliers only with the screen fitted: there the told screen's edges are what is off, and crossings
        // off the edge pull its arc; on a told screen the edges' rms is what the gate holds (max_edge_rms_m).
        if (refine_camera) reweight_edges(pb, q, !pb.refine_screen || round == options.rounds, out);
        if (round == options.rounds) break;
        levenberg_marquardt(pb, q, refine_camera, options.max_iterations);
    }
    conditioning(pb, q, refine_camera, out);
    out.camera = camera_at(camera, q.data(), pb.intrinsic_params(q));
    out.screen = pb.screen(pb.screen_params(q));
    for (std::size_t k = 0; k < n; ++k)
        out.projectors.push_back(
            projector_at(projectors[k], q.data() + kCam + pb.kp * static_cast<int>(k), pb.kp > kProj));
    return out;
}

}  // namespace mogao::autocal
