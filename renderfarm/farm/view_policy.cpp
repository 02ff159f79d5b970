// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/view_policy.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace mogao {
namespace {

void note(std::string& changes, const std::string& what) {
    if (!changes.empty()) changes += ", ";
    changes += what;
}

std::string point(const Eigen::Vector3d& p) { return fmt::format("({:.3g}, {:.3g}, {:.3g})", p.x(), p.y(), p.z()); }

void keep_eye_inside(ViewRequest& v, const VisitableArea& area, std::string& changes) {
    Eigen::Vector3d& eye = v.pose.eye;
    const Eigen::Vector3d requested = eye;
    if (area.radius_m > 0.0) {
        const Eigen::Vector2d offset = Eigen::Vector2d(eye.x(), eye.z()) - area.centre_xz;
        if (offset.norm() > area.radius_m) {
            const Eigen::Vector2d on_rim = area.centre_xz + offset * (area.radius_m / offset.norm());
            eye.x() = on_rim.x();
            eye.z() = on_rim.y();
        }
    } else {
        eye.x() = std::clamp(eye.x(), area.min_xz.x(), area.max_xz.x());
        eye.z() = std::clamp(eye.z(), area.min_xz.y(), area.max_xz.y());
    }
    eye.y() = std::clamp(eye.y(), area.eye_min_m, area.eye_max_m);
    if (eye != requested) note(changes, "eye " + point(requested) + " -> " + point(eye));
}

void keep_to_screen(ViewRequest& v, const CylinderScreen& screen, double max_guard_deg, std::string& changes) {
    const double max_arc = std::min(360.0, screen.arc_deg + 2.0 * max_guard_deg);
    if (std::holds_alternative<PinholeCamera>(v.camera)) {
        v.camera = screen;
        note(changes, "camera pinhole -> the screen's cylinder");
        return;
    }
    CylinderScreen& c = std::get<CylinderScreen>(v.camera);
    const CylinderScreen requested = c;
    c.radius_m = screen.radius_m;
    c.bottom_m = screen.bottom_m;
    c.top_m = screen.top_m;
    c.eye_m = screen.eye_m;
    c.arc_deg = std::min(c.arc_deg, max_arc);
    if (c.radius_m != requested.radius_m || c.bottom_m != requested.bottom_m || c.top_m != requested.top_m ||
        c.eye_m != requested.eye_m)
        note(changes, "cylinder radius, heights and eye -> the screen's");
    if (c.arc_deg != requested.arc_deg)
        note(changes, fmt::format("arc_deg {:g} -> {:g}", requested.arc_deg, c.arc_deg));
}

void keep_to_size(ViewRequest& v, const ImageSize& max, std::string& changes) {
    const ImageSize rendered = render_size(v);
    if (rendered.width <= max.width && rendered.height <= max.height) return;
    const double requested = v.quality.resolution_scale;
    const double fit = std::min(double(max.width) / v.size.width, double(max.height) / v.size.height);
    // render_size rounds to nearest: step down until the rounded size fits (a few ulps at most).
    const auto fits = [&](double scale) {
        return std::lround(v.size.width * scale) <= max.width && std::lround(v.size.height * scale) <= max.height;
    };
    double scale = std::min(requested, fit);
    while (!fits(scale)) scale = std::nextafter(scale, 0.0);
    v.quality.resolution_scale = scale;
    const ImageSize now = render_size(v);
    note(changes,
         fmt::format("resolution_scale {:g} -> {:.4g} ({}x{} -> {}x{} rendered, the appliance's limit {}x{})",
                     requested, scale, rendered.width, rendered.height, now.width, now.height, max.width, max.height));
}

}  // namespace

void ViewPolicy::validate() const {
    if (!(max_guard_deg >= 0.0 && max_guard_deg < 180.0))
        throw std::invalid_argument(fmt::format("view policy: max_guard_deg {} is outside [0, 180)", max_guard_deg));
    if (!(min_fov_deg >= 0.0 && min_fov_deg <= 179.0))
        throw std::invalid_argument(fmt::format("view policy: min_fov_deg {} is outside [0, 179]", min_fov_deg));
    if (screen && !(screen->radius_m > 0.0 && screen->arc_deg > 0.0 && screen->arc_deg <= 360.0 &&
                    screen->top_m > screen->bottom_m))
        throw std::invalid_argument(
            "view policy: screen needs radius > 0, arc in (0, 360] degrees and top above bottom");
    if (max_size &&
        !(max_size->width >= 16 && max_size->width <= 16384 && max_size->height >= 16 && max_size->height <= 16384))
        throw std::invalid_argument(fmt::format("view policy: max_size {}x{} is outside [16, 16384] per side",
                                                max_size->width, max_size->height));
}

ViewDecision apply_view_policy(const ViewRequest& request, const Viewer& viewer, const ViewPolicy& policy) {
    policy.validate();
    ViewDecision d{request, {}};
    if (policy.visitable_area && viewer.visitable) keep_eye_inside(d.view, *viewer.visitable, d.changes);
    if (policy.screen) {
        keep_to_screen(d.view, *policy.screen, policy.max_guard_deg, d.changes);
    } else if (auto* pinhole = std::get_if<PinholeCamera>(&d.view.camera);
               pinhole != nullptr && pinhole->vertical_fov_deg < policy.min_fov_deg) {
        note(d.changes, fmt::format("vertical_fov_deg {:g} -> {:g}", pinhole->vertical_fov_deg, policy.min_fov_deg));
        pinhole->vertical_fov_deg = policy.min_fov_deg;
    }
    if (policy.max_size) keep_to_size(d.view, *policy.max_size, d.changes);
    return d;
}

}  // namespace mogao
