// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/denoise/guide_pass.h"

#include <array>
#include <cerrno>
#include <limits>
#include <optional>
#include <stdexcept>

#include <embree3/rtcore.h>

#include "common/request_limits.h"
#include "renderfarm/trace/camera.h"
#include "renderfarm/trace/render_scene.h"

namespace mogao {
namespace {

constexpr int kBlock = 4;  // 4x4 pixels = one rtcIntersect16 packet, as the renderer traces
constexpr int kLanes = kBlock * kBlock;

std::string size_text(ImageSize s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

}  // namespace

struct GuidePass::Impl {
    Impl(const Scene& s, const std::string& config) : scene(s), geometry(s, config) {}

    const Scene& scene;
    RenderScene geometry;
    std::optional<CameraSetup> camera;
    ImageSize size;

    // Camera rays through the centres of block (x0, y0)'s pixels inside rect; returns the lane mask.
    std::array<int, kLanes> fill(int x0, int y0, const PixelRect& rect, RTCRayHit16& packet) const {
        alignas(64) std::array<int, kLanes> valid{};
        const Eigen::Vector3d& origin = geometry.origin();
        for (int lane = 0; lane < kLanes; ++lane) {
            const auto l = static_cast<std::size_t>(lane);
            const int x = x0 + lane % kBlock, y = y0 + lane / kBlock;
            packet.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
            packet.hit.instID[0][l] = RTC_INVALID_GEOMETRY_ID;
            if (!rect.contains(x, y)) continue;
            valid[l] = -1;
            const Ray ray = generate_ray(*camera, x + 0.5, y + 0.5);
            const Eigen::Vector3f org = (ray.origin - origin).cast<float>();
            const Eigen::Vector3f dir = ray.direction.cast<float>();
            packet.ray.org_x[l] = org.x(), packet.ray.org_y[l] = org.y(), packet.ray.org_z[l] = org.z();
            packet.ray.dir_x[l] = dir.x(), packet.ray.dir_y[l] = dir.y(), packet.ray.dir_z[l] = dir.z();
            packet.ray.tnear[l] = 0.0f;
            packet.ray.tfar[l] = std::numeric_limits<float>::infinity();
            packet.ray.mask[l] = 0xFFFFFFFFu;
            packet.ray.id[l] = static_cast<unsigned>(lane);
        }
        return valid;
    }

    void store(int x0, int y0, const std::array<int, kLanes>& valid, const RTCRayHit16& packet,
               GuideBuffers& guides) const {
        for (std::size_t l = 0; l < kLanes; ++l) {
            if (valid[l] == 0) continue;
            const std::size_t i = guides.pixel(x0 + static_cast<int>(l) % kBlock, y0 + static_cast<int>(l) / kBlock);
            float* albedo = guides.albedo.data() + 3 * i;
            float* normal = guides.normal.data() + 3 * i;
            if (packet.hit.geomID[l] == RTC_INVALID_GEOMETRY_ID) {
                guides.hit[i] = 0;
                guides.depth[i] = 0.0f;
                for (int c = 0; c < 3; ++c) albedo[c] = normal[c] = 0.0f;
                continue;
            }
            const Eigen::Vector3f org(packet.ray.org_x[l], packet.ray.org_y[l], packet.ray.org_z[l]);
            const Eigen::Vector3f dir(packet.ray.dir_x[l], packet.ray.dir_y[l], packet.ray.dir_z[l]);
            const SurfaceHit hit = geometry.surface(
                org, dir, packet.ray.tfar[l], packet.hit.instID[0][l], packet.hit.primID[l], packet.hit.u[l],
                packet.hit.v[l], Eigen::Vector3f(packet.hit.Ng_x[l], packet.hit.Ng_y[l], packet.hit.Ng_z[l]));
            Eigen::Vector3f a = scene.materials[hit.material].albedo;
            if (hit.tinted) a = a.cwiseProduct(hit.tint);
            guides.hit[i] = 1;
            guides.depth[i] = packet.ray.tfar[l];
            for (int c = 0; c < 3; ++c) {
                albedo[c] = a[c];
                normal[c] = hit.shading_normal[c];
            }
        }
    }
};

GuidePass::GuidePass(const Scene& scene, const std::string& embree_config)
    : impl_(std::make_unique<Impl>(scene, embree_config)) {}
GuidePass::~GuidePass() = default;

Status GuidePass::begin_frame(const ViewRequest& request) {
    ImageSize size;
    try {
        size = render_size_for(request);
    } catch (const std::invalid_argument& e) {
        return make_error(EINVAL, std::string("guide pass: ") + e.what());
    }
    impl_->geometry.rebase(request.pose.eye);
    impl_->camera = make_camera_setup(request, size);
    impl_->size = size;
    return {};
}

ImageSize GuidePass::render_size() const { return impl_->size; }

Status GuidePass::render(const PixelRect& rect, GuideBuffers& guides) const {
    const Impl& s = *impl_;
    if (!s.camera) return make_error(EINVAL, "guide pass: begin_frame() must succeed before render()");
    const auto n = static_cast<std::size_t>(s.size.pixel_count());
    if (guides.size != s.size || guides.hit.size() != n || guides.depth.size() != n || guides.albedo.size() != 3 * n ||
        guides.normal.size() != 3 * n) {
        return make_error(EINVAL, "guide pass: guides are " + size_text(guides.size) +
                                      " (or have buffers of the wrong length), the render size is " +
                                      size_text(s.size));
    }
    if (rect.x0 < 0 || rect.y0 < 0 || rect.x1 > s.size.width || rect.y1 > s.size.height) {
        return make_error(EINVAL, "guide pass: rect [" + std::to_string(rect.x0) + ", " + std::to_string(rect.x1) +
                                      ") x [" + std::to_string(rect.y0) + ", " + std::to_string(rect.y1) +
                                      ") is outside the render size " + size_text(s.size));
    }
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    for (int by = rect.y0 - rect.y0 % kBlock; by < rect.y1; by += kBlock) {
        for (int bx = rect.x0 - rect.x0 % kBlock; bx < rect.x1; bx += kBlock) {
            RTCRayHit16 packet{};
            alignas(64) const std::array<int, kLanes> valid = s.fill(bx, by, rect, packet);
            rtcIntersect16(valid.data(), s.geometry.root(), &context, &packet);
            s.store(bx, by, valid, packet, guides);
        }
    }
    return {};
}

Result<GuideBuffers> GuidePass::render_frame(const ViewRequest& request) {
    if (Status s = begin_frame(request); !s.ok()) return s.error();
    GuideBuffers guides(impl_->size);
    if (Status s = render(PixelRect::whole(guides.size), guides); !s.ok()) return s.error();
    return guides;
}

}  // namespace mogao
