// SPDX-License-Identifier: Apache-2.0
// Bundle adjustment of the camera pose and the projector models on the cylinder (bundle_adjust.h).
#include "appliance/autocal/bundle_adjust.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "appliance/autocal/screen_geometry.h"

namespace mogao::autocal {
namespace {

constexpr int kCam = 6;   // camera: position offset (3), rotation vector (3)
constexpr int kProj = 9;  // projector: fx, cx, cy, rotation vector (3), position offset (3)
// Screen (last, when refined): radius offset (m) and arc offset (rad) with refine_screen, then the
// four bow amplitudes (m, ScreenModel::bow_m) with refine_bow.
constexpr int kScreenShape = 2;
constexpr int kScreenBow = 4;

Eigen::Matrix3d rotation_of(const Eigen::Vector3d& w) {
    const double a = w.norm();
    return a < 1e-15 ? Eigen::Matrix3d::Identity() : Eigen::AngleAxisd(a, w / a).toRotationMatrix();
}

DeviceModel camera_at(const DeviceModel& c0, const double* q) {
    DeviceModel c = c0;
    c.position_m = c0.position_m + Eigen::Vector3d(q[0], q[1], q[2]);
    c.rotation = rotation_of(Eigen::Vector3d(q[3], q[4], q[5])) * c0.rotation;
    return c;
}

DeviceModel projector_at(const DeviceModel& p0, const double* q) {
    DeviceModel p = p0;
    const double aspect = p0.fy_px / p0.fx_px;
    p.fx_px = q[0];
    p.fy_px = q[0] * aspect;
    p.cx_px = q[1];
    p.cy_px = q[2];
    p.rotation = rotation_of(Eigen::Vector3d(q[3], q[4], q[5])) * p0.rotation;
    p.position_m = p0.position_m + Eigen::Vector3d(q[6], q[7], q[8]);
    return p;
}

// The screen the parameters describe: the prior's, with the radius and arc offsets and the bow
// when refined.
ScreenModel screen_at(const ScreenModel& s0, const double* qs, bool shape, bool bow) {
    ScreenModel s = s0;
    if (qs == nullptr) return s;
    if (shape) {
        s.radius_m = s0.radius_m + qs[0];
        s.arc_deg = s0.arc_deg + qs[1] * 180.0 / std::numbers::pi;
        qs += kScreenShape;
    }
    if (bow) {
        for (std::size_t i = 0; i < s.bow_m.size(); ++i) s.bow_m[i] = s0.bow_m[i] + qs[i];
    }
    return s;
}

// Residuals of one block: the edges (block -1) or projector k's inlier correspondences. `qs` is the
// screen's parameters (nullptr: the prior's screen, fixed).
struct Problem {
    const ScreenModel& screen0;
    const DeviceModel& camera0;
    const std::vector<DeviceModel>& projectors0;
    const std::vector<EdgeObservation>& edges;
    const std::vector<ProjectorObservations>& obs;
    std::vector<std::vector<int>> inliers;  // per projector, indices into obs[k]
    std::vector<double> sigma_px;
    double sigma_m = 0.005;
    bool refine_screen = false;
    bool refine_bow = false;
    Eigen::Index screen_index = 0;  // first screen parameter in q

    [[nodiscard]] int screen_count() const {
        return (refine_screen ? kScreenShape : 0) + (refine_bow ? kScreenBow : 0);
    }
    [[nodiscard]] const double* screen_params(const Eigen::VectorXd& q) const {
        return screen_count() > 0 ? q.data() + screen_index : nullptr;
    }
    [[nodiscard]] ScreenModel screen(const double* qs) const {
        return screen_at(screen0, qs, refine_screen, refine_bow);
    }

    [[nodiscard]] Eigen::VectorXd edge_residuals(const double* qc, const double* qs) const {
        const ScreenModel screen = this->screen(qs);
        const DeviceModel c = camera_at(camera0, qc);
        const double half = screen.arc_deg * std::numbers::pi / 360.0;
        Eigen::VectorXd r(static_cast<Eigen::Index>(edges.size()));
        for (std::size_t i = 0; i < edges.size(); ++i) {
            const Eigen::Vector3d x = ray_on_screen(screen, c, edges[i].ray);
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
            r[static_cast<Eigen::Index>(i)] = std::isfinite(e) ? e / sigma_m : 0.0;
        }
        return r;
    }

    [[nodiscard]] Eigen::VectorXd projector_residuals(std::size_t k, const double* qc, const double* qp,
                                                      const double* qs) const {
        const ScreenModel screen = this->screen(qs);
        const DeviceModel c = camera_at(camera0, qc);
        const DeviceModel p = projector_at(projectors0[k], qp);
        const Eigen::Matrix3d rt = p.rotation.transpose();
        const std::vector<int>& use = inliers[k];
        Eigen::VectorXd r(2 * static_cast<Eigen::Index>(use.size()));
        for (std::size_t u = 0; u < use.size(); ++u) {
            const auto i = static_cast<std::size_t>(use[u]);
            const Eigen::Vector3d x = ray_on_screen(screen, c, obs[k].rays[i]);
            const Eigen::Vector3d d = rt * (x - p.position_m);
            Eigen::Vector2d e(1e3, 1e3);  // behind the projector or missed: a large, constant residual
            if (d.allFinite() && d.z() > 1e-9) {
                e = Eigen::Vector2d(p.fx_px * d.x() / d.z() + p.cx_px, p.fy_px * d.y() / d.z() + p.cy_px) -
                    obs[k].projector[i];
            }
            if (!obs[k].sigma_px.empty()) e = e.cwiseQuotient(obs[k].sigma_px[i]);
            r.segment<2>(2 * static_cast<Eigen::Index>(u)) = e / sigma_px[k];
        }
        return r;
    }
};

double step_of(int j) {  // forward-difference steps: pixels for intrinsics, metres and radians for poses
    return j < 3 ? 1e-4 : 1e-8;
}

// Adds block's J^T J and J^T r (columns: the camera's, if refined, and the block's own) to the system.
void accumulate(const Problem& pb, const Eigen::VectorXd& q, int block, bool refine_camera, Eigen::MatrixXd& jtj,
                Eigen::VectorXd& jtr, double& cost) {
    const auto eval = [&](const Eigen::VectorXd& v) {
        return block < 0 ? pb.edge_residuals(v.data(), pb.screen_params(v))
                         : pb.projector_residuals(static_cast<std::size_t>(block), v.data(),
                                                  v.data() + kCam + kProj * block, pb.screen_params(v));
    };
    const Eigen::VectorXd r0 = eval(q);
    cost += r0.squaredNorm();
    std::vector<int> cols;
    if (refine_camera) {
        for (int j = 0; j < kCam; ++j) cols.push_back(j);
    }
    if (block >= 0) {
        for (int j = 0; j < kProj; ++j) cols.push_back(kCam + kProj * block + j);
    }
    for (int j = 0; j < pb.screen_count(); ++j) cols.push_back(static_cast<int>(pb.screen_index) + j);
    Eigen::MatrixXd jac(r0.size(), static_cast<Eigen::Index>(cols.size()));
    for (std::size_t c = 0; c < cols.size(); ++c) {
        Eigen::VectorXd v = q;
        const int idx = cols[c];
        const double h = idx < kCam || idx >= pb.screen_index ? 1e-8 : step_of(idx - kCam - kProj * block);
        v[idx] += h;
        jac.col(static_cast<Eigen::Index>(c)) = (eval(v) - r0) / h;
    }
    const Eigen::MatrixXd a = jac.transpose() * jac;
    const Eigen::VectorXd b = jac.transpose() * r0;
    for (std::size_t i = 0; i < cols.size(); ++i) {
        jtr[cols[i]] += b[static_cast<Eigen::Index>(i)];
        for (std::size_t j = 0; j < cols.size(); ++j) {
            jtj(cols[i], cols[j]) += a(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
        }
    }
}

double total_cost(const Problem& pb, const Eigen::VectorXd& q, bool refine_camera) {
    double cost = refine_camera ? pb.edge_residuals(q.data(), pb.screen_params(q)).squaredNorm() : 0.0;
    for (std::size_t k = 0; k < pb.obs.size(); ++k) {
        cost += pb.projector_residuals(k, q.data(), q.data() + kCam + kProj * static_cast<int>(k), pb.screen_params(q))
                    .squaredNorm();
    }
    return cost;
}

void levenberg_marquardt(const Problem& pb, Eigen::VectorXd& q, bool refine_camera, int max_iterations) {
    double lambda = 1e-3;
    const int blocks = static_cast<int>(pb.obs.size());
    for (int iter = 0; iter < max_iterations; ++iter) {
        Eigen::MatrixXd jtj = Eigen::MatrixXd::Zero(q.size(), q.size());
        Eigen::VectorXd jtr = Eigen::VectorXd::Zero(q.size());
        double cost = 0.0;
        for (int b = refine_camera ? -1 : 0; b < blocks; ++b) accumulate(pb, q, b, refine_camera, jtj, jtr, cost);
        if (!refine_camera) jtj.topLeftCorner<kCam, kCam>().setIdentity();  // fixed: zero step
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

}  // namespace

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
    Problem pb{screen, camera, projectors, edges, observations, {}, std::vector<double>(n, 1.0), 0.005};
    // The screen needs the edges (its ends and heights) and the camera refined with it.
    pb.refine_screen = options.refine_screen && options.refine_camera && !edges.empty();
    pb.refine_bow = options.refine_bow && options.refine_camera && !edges.empty();
    pb.screen_index = kCam + kProj * static_cast<Eigen::Index>(n);
    Eigen::VectorXd q = Eigen::VectorXd::Zero(pb.screen_index + pb.screen_count());
    for (std::size_t k = 0; k < n; ++k) {
        const ProjectorObservations& o = observations[k];
        if (o.rays.size() != o.projector.size() || o.rays.size() < 10) {
            throw std::invalid_argument("bundle_adjust: projector " + std::to_string(k) +
                                        ": needs >= 10 correspondences with as many rays as positions");
        }
        pb.inliers.emplace_back(o.rays.size());
        for (std::size_t i = 0; i < o.rays.size(); ++i) pb.inliers[k][i] = static_cast<int>(i);
        const auto base = static_cast<Eigen::Index>(kCam + kProj * k);
        q[base] = projectors[k].fx_px;
        q[base + 1] = projectors[k].cx_px;
        q[base + 2] = projectors[k].cy_px;
    }
    const bool refine_camera = options.refine_camera && !edges.empty();
    BundleResult out;
    out.rms_px.assign(n, 0.0);
    out.rms_sigma.assign(n, 0.0);
    out.inliers.assign(n, 0);
    for (int round = 0; round <= options.rounds; ++round) {
        // Re-weight from the current residuals (sigma = rms), then drop outliers (> 4x the median).
        for (std::size_t k = 0; k < n; ++k) {
            const double old_sigma = pb.sigma_px[k];
            const Eigen::VectorXd r =
                pb.projector_residuals(k, q.data(), q.data() + kCam + kProj * k, pb.screen_params(q)) * old_sigma;
            std::vector<double> err(pb.inliers[k].size());
            for (std::size_t u = 0; u < err.size(); ++u) err[u] = r.segment<2>(2 * static_cast<Eigen::Index>(u)).norm();
            std::vector<double> sorted = err;
            std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
            const double limit = 4.0 * std::max(sorted[sorted.size() / 2], 0.01);
            std::vector<int> keep;
            double ss = 0.0;
            double ss_px = 0.0;
            for (std::size_t u = 0; u < err.size(); ++u) {
                if (round == options.rounds || err[u] <= limit) {
                    const auto i = static_cast<std::size_t>(pb.inliers[k][u]);
                    const Eigen::Vector2d s =
                        observations[k].sigma_px.empty() ? Eigen::Vector2d(1.0, 1.0) : observations[k].sigma_px[i];
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
        if (refine_camera) {
            out.edge_rms_m = pb.sigma_m * pb.edge_residuals(q.data(), pb.screen_params(q)).norm() /
                             std::sqrt(std::max<double>(1.0, static_cast<double>(edges.size())));
            pb.sigma_m = std::max(out.edge_rms_m, 1e-5);
        }
        if (round == options.rounds) break;
        levenberg_marquardt(pb, q, refine_camera, options.max_iterations);
    }
    out.camera = camera_at(camera, q.data());
    out.screen = pb.screen(pb.screen_params(q));
    for (std::size_t k = 0; k < n; ++k)
        out.projectors.push_back(projector_at(projectors[k], q.data() + kCam + kProj * k));
    return out;
}

}  // namespace mogao::autocal
