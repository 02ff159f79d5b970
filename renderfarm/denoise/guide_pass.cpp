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
#include "renderfarm/trace/embree_packets.h"
#include "renderfarm/trace/render_scene.h"

namespace mogao {
namespace {

constexpr int kBlock = 4;  // 4x4 pixels = one rtcIntersect16 packet, as the renderer traces
constexpr int kLanes = kBlock * kBlock;

std::string size_text(ImageSize s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

}  // namespace

struct GuidePass::Impl {
    Impl(const Scene& s, const std::string& config)
        : scene(s), owned(std::make_unique<RenderScene>(s, config)), geometry(*owned) {}
    Impl(const Scene& s, const RenderScene& shared) : scene(s), geometry(shared) {}

    const Scene& scene;
    std::unique_ptr<RenderScene> owned;  // null when the geometry is a Renderer's
    const RenderScene& geometry;
    std::optional<CameraSetup> camera;
    float spread = 0.0f;  // one pixel's ray-cone spread (the guide's one sample per pixel)
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

    // Stores the hits of block (x0, y0) at their pixels less (ox, oy) (the window's origin).
    void store(int x0, int y0, int ox, int oy, const std::array<int, kLanes>& valid, const RTCRayHit16& packet,
               GuideBuffers& guides) const {
        for (std::size_t l = 0; l < kLanes; ++l) {
            if (valid[l] == 0) continue;
            const std::size_t i =
                guides.pixel(x0 + static_cast<int>(l) % kBlock - ox, y0 + static_cast<int>(l) / kBlock - oy);
            if (packet.hit.geomID[l] == RTC_INVALID_GEOMETRY_ID) {
                guides.set_sky(i);
                continue;
            }
            const Eigen::Vector3f org(packet.ray.org_x[l], packet.ray.org_y[l], packet.ray.org_z[l]);
            const Eigen::Vector3f dir(packet.ray.dir_x[l], packet.ray.dir_y[l], packet.ray.dir_z[l]);
            const SurfaceHit hit =
                geometry.surface(org, dir, packet.ray.tfar[l], packet.hit.instID[0][l], packet.hit.geomID[l],
                                 packet.hit.primID[l], packet.hit.u[l], packet.hit.v[l],
                                 Eigen::Vector3f(packet.hit.Ng_x[l], packet.hit.Ng_y[l], packet.hit.Ng_z[l]),
                                 spread * packet.ray.tfar[l]);
            Eigen::Vector3f a = scene.materials[hit.material].albedo;
            if (hit.tinted) a = a.cwiseProduct(hit.tint);
            guides.set_surface(i, a.data(), hit.shading_normal.data(), packet.ray.tfar[l]);
        }
    }
};

GuidePass::GuidePass(const Scene& scene, const std::string& embree_config)
    : impl_(std::make_unique<Impl>(scene, embree_config)) {}
GuidePass::GuidePass(const Scene& scene, const RenderScene& geometry)
    : impl_(std::make_unique<Impl>(scene, geometry)) {}
GuidePass::~GuidePass() = default;

Status GuidePass::begin_frame(const ViewRequest& request) {
    ImageSize size;
    try {
        size = render_size_for(request);
    } catch (const std::invalid_argument& e) {
        return make_error(EINVAL, std::string("guide pass: ") + e.what());
    }
    if (impl_->owned) impl_->owned->rebase(request.pose.eye);
    impl_->camera = make_camera_setup(request, size);
    impl_->spread = static_cast<float>(camera_cone_spread(*impl_->camera, 1));
    impl_->size = size;
    return {};
}

ImageSize GuidePass::render_size() const { return impl_->size; }

Status GuidePass::render(const PixelRect& rect, GuideBuffers& guides) const {
    if (impl_->camera && guides.size != impl_->size) {
        return make_error(EINVAL, "guide pass: guides are " + size_text(guides.size) + ", the render size is " +
                                      size_text(impl_->size));
    }
    return render(rect, guides, 0, 0);
}

Status GuidePass::render(const PixelRect& rect, GuideBuffers& window, int origin_x, int origin_y) const {
    const Impl& s = *impl_;
    if (!s.camera) return make_error(EINVAL, "guide pass: begin_frame() must succeed before render()");
    const auto n = static_cast<std::size_t>(window.size.pixel_count());
    if (window.size.width < 0 || window.size.height < 0 || window.hit.size() != n || window.depth.size() != n ||
        window.albedo.size() != 3 * n || window.normal.size() != 3 * n) {
        return make_error(EINVAL, "guide pass: the guide buffers do not hold " + size_text(window.size) +
                                      " pixels (hit, depth: W*H; albedo, normal: W*H*3)");
    }
    const PixelRect placed{origin_x, origin_y, origin_x + window.size.width, origin_y + window.size.height};
    if (rect.x0 < 0 || rect.y0 < 0 || rect.x1 > s.size.width || rect.y1 > s.size.height ||
        intersect(rect, placed) != rect) {
        return make_error(EINVAL, "guide pass: rect [" + std::to_string(rect.x0) + ", " + std::to_string(rect.x1) +
                                      ") x [" + std::to_string(rect.y0) + ", " + std::to_string(rect.y1) +
                                      ") is outside the render size " + size_text(s.size) + " or the " +
                                      size_text(window.size) + " window at (" + std::to_string(origin_x) + ", " +
                                      std::to_string(origin_y) + ")");
    }
    if (rect.empty()) return {};
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    // At the native width, as the renderer traces its camera packets: Embree runs a 16-wide call
    // ray by ray where it has no 16-wide kernels (embree_packets.h), the usual case (embree_device.h).
    const int width = native_packet_width(s.geometry.root());
    for (int by = rect.y0 - rect.y0 % kBlock; by < rect.y1; by += kBlock) {
        for (int bx = rect.x0 - rect.x0 % kBlock; bx < rect.x1; bx += kBlock) {
            RTCRayHit16 packet{};
            alignas(64) const std::array<int, kLanes> valid = s.fill(bx, by, rect, packet);
            intersect16_at(width, valid.data(), s.geometry.root(), &context, packet);
            s.store(bx, by, origin_x, origin_y, valid, packet, window);
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
