// SPDX-License-Identifier: Apache-2.0
// RAII for GBM objects on a DRM fd: the gbm_device, a gbm_surface (the EGL window of one KMS
// output), a locked front buffer (gbm_bo, released back to its surface), and the DRM framebuffer
// of a bo, owned by the bo itself as its user data (drmModeRmFB when GBM destroys the bo).
// Order of destruction: LockedBo before its GbmSurface, every GbmSurface (and the EGL display on
// the device) before the GbmDevice, the GbmDevice before the DRM fd. All are move-only owners
// (common/unique_handle.h); a moved-from one owns nothing.
#pragma once

#include <gbm.h>

#include <cstdint>

#include "common/pixel_rect.h"
#include "common/result.h"
#include "common/unique_handle.h"

namespace mogao {

class GbmDevice {
public:
    // `drm_fd` stays owned by the caller (DrmDevice) and must outlive the device.
    [[nodiscard]] static Result<GbmDevice> create(int drm_fd);
    [[nodiscard]] gbm_device* get() const { return device_.get(); }

private:
    explicit GbmDevice(gbm_device* device) : device_(device) {}
    UniquePtr<gbm_device, &gbm_device_destroy> device_;
};

class GbmSurface {
public:
    // `format`: a GBM_FORMAT_* fourcc; `flags`: GBM_BO_USE_SCANOUT | GBM_BO_USE_RENDERING for KMS.
    [[nodiscard]] static Result<GbmSurface> create(const GbmDevice& device, ImageSize size, std::uint32_t format,
                                                   std::uint32_t flags);
    [[nodiscard]] gbm_surface* get() const { return surface_.get(); }
    // False while every buffer is locked (on screen or waiting for a flip): don't render yet.
    [[nodiscard]] bool has_free_buffers() const { return gbm_surface_has_free_buffers(surface_.get()) != 0; }

private:
    explicit GbmSurface(gbm_surface* surface) : surface_(surface) {}
    UniquePtr<gbm_surface, &gbm_surface_destroy> surface_;
};

// The front buffer of a gbm_surface, locked after eglSwapBuffers; released to the surface (to be
// rendered into again) on destruction, i.e. once the kernel no longer scans it out.
class LockedBo {
public:
    LockedBo() = default;
    // EBUSY when the surface has no new front buffer (eglSwapBuffers not called since the last lock).
    [[nodiscard]] static Result<LockedBo> lock_front(const GbmSurface& surface);
    [[nodiscard]] gbm_bo* get() const { return bo_.get().bo; }
    [[nodiscard]] bool valid() const { return bo_.valid(); }
    void reset() noexcept { bo_.reset(); }

private:
    // The bo with the surface it goes back to: both move together, {nullptr, nullptr} owns nothing.
    struct Locked {
        gbm_surface* surface = nullptr;
        gbm_bo* bo = nullptr;
        bool operator==(const Locked&) const = default;
    };
    struct Traits {
        using Value = Locked;
        static constexpr Locked null() noexcept { return {}; }
        static void close(Locked locked) noexcept { gbm_surface_release_buffer(locked.surface, locked.bo); }
    };
    LockedBo(gbm_surface* surface, gbm_bo* bo) : bo_(Locked{surface, bo}) {}
    UniqueHandle<Traits> bo_;
};

// The DRM framebuffer id scanning out `bo`: added (drmModeAddFB2, with the bo's modifier when it
// has one) on the first call for a bo and cached as the bo's user data, a DrmFramebuffer that
// GBM destroys (drmModeRmFB) together with the bo. `drm_fd` must outlive the bo.
[[nodiscard]] Result<std::uint32_t> framebuffer_for(gbm_bo* bo, int drm_fd);

}  // namespace mogao
