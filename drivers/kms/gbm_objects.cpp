// SPDX-License-Identifier: Apache-2.0
#include "drivers/kms/gbm_objects.h"

#include <drm_fourcc.h>

#include <memory>
#include <string>

#include "drivers/kms/drm_device.h"

namespace mogao {

Result<GbmDevice> GbmDevice::create(int drm_fd) {
    gbm_device* device = gbm_create_device(drm_fd);
    if (device == nullptr) return errno_error("gbm_create_device");
    return GbmDevice(device);
}

Result<GbmSurface> GbmSurface::create(const GbmDevice& device, ImageSize size, std::uint32_t format,
                                      std::uint32_t flags) {
    if (size.width <= 0 || size.height <= 0) return make_error(EINVAL, "gbm_surface_create: empty size");
    gbm_surface* surface = gbm_surface_create(device.get(), static_cast<std::uint32_t>(size.width),
                                              static_cast<std::uint32_t>(size.height), format, flags);
    if (surface == nullptr) {
        return errno_error("gbm_surface_create(" + std::to_string(size.width) + "x" + std::to_string(size.height) +
                           ")");
    }
    return GbmSurface(surface);
}

Result<LockedBo> LockedBo::lock_front(const GbmSurface& surface) {
    gbm_bo* bo = gbm_surface_lock_front_buffer(surface.get());
    if (bo == nullptr) return make_error(EBUSY, "gbm_surface_lock_front_buffer: no new front buffer");
    return LockedBo(surface.get(), bo);
}

Result<std::uint32_t> framebuffer_for(gbm_bo* bo, int drm_fd) {
    if (auto* existing = static_cast<DrmFramebuffer*>(gbm_bo_get_user_data(bo))) return existing->id();

    std::uint32_t handles[4] = {};
    std::uint32_t strides[4] = {};
    std::uint32_t offsets[4] = {};
    std::uint64_t modifiers[4] = {};
    const int planes = gbm_bo_get_plane_count(bo);
    const std::uint64_t modifier = gbm_bo_get_modifier(bo);
    for (int i = 0; i < planes && i < 4; ++i) {
        const auto k = static_cast<std::size_t>(i);
        handles[k] = gbm_bo_get_handle_for_plane(bo, i).u32;
        strides[k] = gbm_bo_get_stride_for_plane(bo, i);
        offsets[k] = gbm_bo_get_offset(bo, i);
        modifiers[k] = modifier;
    }
    const std::uint32_t width = gbm_bo_get_width(bo);
    const std::uint32_t height = gbm_bo_get_height(bo);
    const std::uint32_t format = gbm_bo_get_format(bo);
    std::uint32_t id = 0;
    int ret = -1;
    if (modifier != DRM_FORMAT_MOD_INVALID) {
        ret = drmModeAddFB2WithModifiers(drm_fd, width, height, format, handles, strides, offsets, modifiers, &id,
                                         DRM_MODE_FB_MODIFIERS);
    }
    // Drivers without modifier support (and buffers without one) take the implicit layout.
    if (ret != 0) ret = drmModeAddFB2(drm_fd, width, height, format, handles, strides, offsets, &id, 0);
    if (ret != 0) return errno_error("drmModeAddFB2");
    // Ownership passes to the bo: GBM calls the destructor when it destroys the bo.
    auto fb = std::make_unique<DrmFramebuffer>(drm_fd, id);
    gbm_bo_set_user_data(bo, fb.release(), [](gbm_bo*, void* data) { delete static_cast<DrmFramebuffer*>(data); });
    return id;
}

}  // namespace mogao
