// RAII for GBM objects on a DRM fd: the gbm_device, a gbm_surface (the EGL window of one KMS
// output), a locked front buffer (gbm_bo, released back to its surface), and the DRM framebuffer
// of a bo, owned by the bo itself as its user data (drmModeRmFB when GBM destroys the bo).
// Order of destruction: LockedBo before its GbmSurface, every GbmSurface (and the EGL display on
// the device) before the GbmDevice, the GbmDevice before the DRM fd.
#pragma once

#include <gbm.h>

#include <cstdint>
#include <utility>

#include "common/result.h"
#include "common/pixel_rect.h"

namespace mogao {

class GbmDevice {
public:
    // `drm_fd` stays owned by the caller (DrmDevice) and must outlive the device.
    [[nodiscard]] static Result<GbmDevice> create(int drm_fd);
    GbmDevice(GbmDevice&& other) noexcept : device_(std::exchange(other.device_, nullptr)) {}
    GbmDevice& operator=(GbmDevice&&) = delete;
    GbmDevice(const GbmDevice&) = delete;
    GbmDevice& operator=(const GbmDevice&) = delete;
    ~GbmDevice() {
        if (device_ != nullptr) gbm_device_destroy(device_);
    }
    [[nodiscard]] gbm_device* get() const { return device_; }

private:
    explicit GbmDevice(gbm_device* device) : device_(device) {}
    gbm_device* device_ = nullptr;
};

class GbmSurface {
public:
    // `format`: a GBM_FORMAT_* fourcc; `flags`: GBM_BO_USE_SCANOUT | GBM_BO_USE_RENDERING for KMS.
    [[nodiscard]] static Result<GbmSurface> create(const GbmDevice& device, ImageSize size, std::uint32_t format,
                                                   std::uint32_t flags);
    GbmSurface(GbmSurface&& other) noexcept : surface_(std::exchange(other.surface_, nullptr)) {}
    GbmSurface& operator=(GbmSurface&&) = delete;
    GbmSurface(const GbmSurface&) = delete;
    GbmSurface& operator=(const GbmSurface&) = delete;
    ~GbmSurface() {
        if (surface_ != nullptr) gbm_surface_destroy(surface_);
    }
    [[nodiscard]] gbm_surface* get() const { return surface_; }
    // False while every buffer is locked (on screen or waiting for a flip): don't render yet.
    [[nodiscard]] bool has_free_buffers() const { return gbm_surface_has_free_buffers(surface_) != 0; }

private:
    explicit GbmSurface(gbm_surface* surface) : surface_(surface) {}
    gbm_surface* surface_ = nullptr;
};

// The front buffer of a gbm_surface, locked after eglSwapBuffers; released to the surface (to be
// rendered into again) on destruction, i.e. once the kernel no longer scans it out.
class LockedBo {
public:
    LockedBo() = default;
    // EBUSY when the surface has no new front buffer (eglSwapBuffers not called since the last lock).
    [[nodiscard]] static Result<LockedBo> lock_front(const GbmSurface& surface);
    LockedBo(LockedBo&& other) noexcept
        : surface_(std::exchange(other.surface_, nullptr)), bo_(std::exchange(other.bo_, nullptr)) {}
    LockedBo& operator=(LockedBo&& other) noexcept {
        if (this != &other) {
            reset();
            surface_ = std::exchange(other.surface_, nullptr);
            bo_ = std::exchange(other.bo_, nullptr);
        }
        return *this;
    }
    LockedBo(const LockedBo&) = delete;
    LockedBo& operator=(const LockedBo&) = delete;
    ~LockedBo() { reset(); }
    [[nodiscard]] gbm_bo* get() const { return bo_; }
    [[nodiscard]] bool valid() const { return bo_ != nullptr; }
    void reset() noexcept {
        if (bo_ != nullptr) gbm_surface_release_buffer(surface_, std::exchange(bo_, nullptr));
    }

private:
    LockedBo(gbm_surface* surface, gbm_bo* bo) : surface_(surface), bo_(bo) {}
    gbm_surface* surface_ = nullptr;
    gbm_bo* bo_ = nullptr;
};

// The DRM framebuffer id scanning out `bo`: added (drmModeAddFB2, with the bo's modifier when it
// has one) on the first call for a bo and cached as the bo's user data, a DrmFramebuffer that
// GBM destroys (drmModeRmFB) together with the bo. `drm_fd` must outlive the bo.
[[nodiscard]] Result<std::uint32_t> framebuffer_for(gbm_bo* bo, int drm_fd);

}  // namespace mogao
