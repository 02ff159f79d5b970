// SPDX-License-Identifier: Apache-2.0
// The camera's vignetting from the projectors' full-white images (camera_vignetting.h, model there).
#include "appliance/autocal/camera_vignetting.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

namespace mogao::autocal {

double radial_rho2(const DeviceModel& d, double x, double y) {
    const double half_diagonal = 0.5 * std::hypot(d.resolution.width, d.resolution.height);
    return (std::pow(x - d.cx_px, 2) + std::pow(y - d.cy_px, 2)) / (half_diagonal * half_diagonal);
}

double vignetting_at(const CameraVignetting& v, double rho2) {
    if (!v.measured) return 1.0;
    return std::max(0.05, 1.0 - v.a * rho2 - v.b * rho2 * rho2);
}

CameraVignetting fit_camera_vignetting(const std::vector<FlatFieldSample>& samples, std::size_t projectors,
                                       double prior_sigma) {
    if (!(prior_sigma > 0.0)) throw std::invalid_argument("fit_camera_vignetting: prior_sigma must be > 0");
    if (samples.size() < 10) {
        throw std::invalid_argument("fit_camera_vignetting: " + std::to_string(samples.size()) +
                                    " samples (need >= 10)");
    }
    const long n = static_cast<long>(projectors);
    const long m = 2 * n + 2;  // A_k, f_k, a, b
    Eigen::VectorXd theta = Eigen::VectorXd::Zero(m);
    std::vector<double> count(projectors, 0.0);
    for (const FlatFieldSample& s : samples) {
        if (s.projector >= projectors) {
            throw std::invalid_argument("fit_camera_vignetting: a sample of projector " + std::to_string(s.projector) +
                                        " of " + std::to_string(projectors));
        }
        theta[static_cast<long>(s.projector)] += s.light;
        count[s.projector] += 1.0;
    }
    for (long k = 0; k < n; ++k) theta[k] /= std::max(1.0, count[static_cast<std::size_t>(k)]);
    const double prior = 1.0 / (prior_sigma * prior_sigma);
    Eigen::MatrixXd h(m, m);
    for (int it = 0; it < 30; ++it) {
        Eigen::MatrixXd jtj = Eigen::MatrixXd::Zero(m, m);
        Eigen::VectorXd jtr = Eigen::VectorXd::Zero(m);
        double sse = 0.0;
        for (const FlatFieldSample& s : samples) {
            const long k = static_cast<long>(s.projector);
            const double amp = theta[k];
            const double f = 1.0 - theta[n + k] * s.projector_rho2;
            const double c = s.camera_rho2;
            const double v = 1.0 - theta[2 * n] * c - theta[2 * n + 1] * c * c;
            const double r = s.light - amp * f * v;
            // The model's derivatives: its non-zero Jacobian entries, at A_k, f_k, a, b.
            const std::array<long, 4> at{k, n + k, 2 * n, 2 * n + 1};
            const std::array<double, 4> j{f * v, -amp * s.projector_rho2 * v, -amp * f * c, -amp * f * c * c};
            for (std::size_t p = 0; p < 4; ++p) {
                jtr[at[p]] += j[p] * r;
                for (std::size_t q = 0; q < 4; ++q) jtj(at[p], at[q]) += j[p] * j[q];
            }
            sse += r * r;
        }
        // MAP: the data weighted by the residual's variance, the prior on a and b around 0.
        const double noise = std::max(sse / static_cast<double>(samples.size()), 1e-12);
        h = jtj / noise;
        Eigen::VectorXd g = jtr / noise;
        for (const long p : {2 * n, 2 * n + 1}) {
            h(p, p) += prior;
            g[p] -= prior * theta[p];
        }
        const Eigen::VectorXd step = h.ldlt().solve(g);
        theta += step;
        if (step.tail(2).norm() < 1e-7 && step.segment(n, n).norm() < 1e-7) break;
    }
    CameraVignetting out;
    out.a = theta[2 * n];
    out.b = theta[2 * n + 1];
    out.corner = 1.0 - out.a - out.b;
    const Eigen::MatrixXd cov = h.inverse();
    out.corner_sigma =
        std::sqrt(std::max(0.0, cov(2 * n, 2 * n) + cov(2 * n + 1, 2 * n + 1) + 2.0 * cov(2 * n, 2 * n + 1)));
    for (long k = 0; k < n; ++k) out.projector_falloff.push_back(theta[n + k]);
    out.samples = static_cast<int>(samples.size());
    double sse = 0.0, light = 0.0;
    for (const FlatFieldSample& s : samples) {
        const long k = static_cast<long>(s.projector);
        const double c = s.camera_rho2;
        const double model = theta[k] * (1.0 - theta[n + k] * s.projector_rho2) * (1.0 - out.a * c - out.b * c * c);
        sse += (s.light - model) * (s.light - model);
        light += s.light;
    }
    out.rms = std::sqrt(sse / static_cast<double>(samples.size())) /
              std::max(light / static_cast<double>(samples.size()), 1e-12);
    out.measured = true;
    return out;
}

}  // namespace mogao::autocal
