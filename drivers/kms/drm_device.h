// SPDX-License-Identifier: Apache-2.0
// RAII for DRM/KMS kernel objects (libdrm): the device fd, the drmMode* structures libdrm
// allocates (freed with their drmModeFree* function), property blobs and framebuffers.
// Errors: Result/Status (common/result.h) with the kernel's errno (ENOENT, EACCES, EBUSY,
// EINVAL, ...) and a message naming the call and the object id.
#pragma once

#include <xf86drm.h>
#include <xf86drmMode.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "common/result.h"
#include "common/unique_fd.h"
#include "common/unique_handle.h"

namespace mogao {

// libdrm structures, each freed with its matching drmModeFree* function.
using DrmResources = UniquePtr<drmModeRes, &drmModeFreeResources>;
using DrmConnector = UniquePtr<drmModeConnector, &drmModeFreeConnector>;
using DrmEncoder = UniquePtr<drmModeEncoder, &drmModeFreeEncoder>;
using DrmCrtc = UniquePtr<drmModeCrtc, &drmModeFreeCrtc>;
using DrmPlaneResources = UniquePtr<drmModePlaneRes, &drmModeFreePlaneResources>;
using DrmPlane = UniquePtr<drmModePlane, &drmModeFreePlane>;
using DrmObjectProperties = UniquePtr<drmModeObjectProperties, &drmModeFreeObjectProperties>;
using DrmProperty = UniquePtr<drmModePropertyRes, &drmModeFreeProperty>;
using DrmAtomicRequest = UniquePtr<drmModeAtomicReq, &drmModeAtomicFree>;

// A KMS object id together with the DRM fd it lives on (its destroy call needs both). {-1, 0}
// owns nothing: what a moved-from PropertyBlob or DrmFramebuffer holds.
struct DrmObjectId {
    int fd = -1;
    std::uint32_t id = 0;
    bool operator==(const DrmObjectId&) const = default;
};

// The /dev/dri/card* nodes under `dir`, sorted by number (card0, card1, ...). Empty if none.
[[nodiscard]] std::vector<std::filesystem::path> list_drm_cards(const std::filesystem::path& dir = "/dev/dri");

// "HDMI-A-1": the kernel's connector type name and the connector's type id.
[[nodiscard]] std::string connector_name(const drmModeConnector& connector);

// An open KMS device (primary node). The fd is opened O_RDWR | O_CLOEXEC | O_NONBLOCK:
// non-blocking so that dispatching page-flip events never stalls the kiosk's event loop.
class DrmDevice {
public:
    // ENOENT/EACCES from open(2); ENODEV when the node is not a KMS device (no mode resources).
    [[nodiscard]] static Result<DrmDevice> open(const std::filesystem::path& path);

    [[nodiscard]] int fd() const { return fd_.get(); }
    [[nodiscard]] const std::filesystem::path& path() const { return path_; }

    // DRM_CLIENT_CAP_UNIVERSAL_PLANES (list primary/cursor planes too) and, when `atomic`,
    // DRM_CLIENT_CAP_ATOMIC. EOPNOTSUPP when the driver refuses (no atomic modesetting).
    [[nodiscard]] Status enable_client_caps(bool atomic) const;

    [[nodiscard]] Result<DrmResources> resources() const;
    [[nodiscard]] Result<DrmConnector> connector(std::uint32_t id) const;
    [[nodiscard]] Result<DrmEncoder> encoder(std::uint32_t id) const;
    [[nodiscard]] Result<DrmCrtc> crtc(std::uint32_t id) const;
    [[nodiscard]] Result<DrmPlaneResources> plane_resources() const;
    [[nodiscard]] Result<DrmPlane> plane(std::uint32_t id) const;

private:
    DrmDevice(UniqueFd fd, std::filesystem::path path) : fd_(std::move(fd)), path_(std::move(path)) {}
    UniqueFd fd_;
    std::filesystem::path path_;
};

// Property names -> ids (and current values) of one KMS object, read once so that atomic
// requests are built without string lookups per frame.
class PropertyMap {
public:
    // `type`: DRM_MODE_OBJECT_CONNECTOR, DRM_MODE_OBJECT_CRTC or DRM_MODE_OBJECT_PLANE.
    [[nodiscard]] static Result<PropertyMap> query(int fd, std::uint32_t object_id, std::uint32_t type);
    // ENOENT naming the object and the property when it has no such property.
    [[nodiscard]] Result<std::uint32_t> id(std::string_view name) const;
    // The property's value when it was queried; ENOENT as id().
    [[nodiscard]] Result<std::uint64_t> value(std::string_view name) const;
    [[nodiscard]] std::uint32_t object_id() const { return object_id_; }

private:
    struct Entry {
        std::string name;
        std::uint32_t id;
        std::uint64_t value;
    };
    [[nodiscard]] const Entry* find(std::string_view name) const;
    std::uint32_t object_id_ = 0;
    std::vector<Entry> entries_;
};

// A property blob (e.g. a CRTC's MODE_ID). Destroyed with drmModeDestroyPropertyBlob; the kernel
// keeps its own reference while a committed state uses it. `fd` must outlive the blob.
class PropertyBlob {
public:
    [[nodiscard]] static Result<PropertyBlob> create(int fd, const void* data, std::size_t size);
    [[nodiscard]] std::uint32_t id() const { return blob_.get().id; }

private:
    struct Traits {
        using Value = DrmObjectId;
        static constexpr DrmObjectId null() noexcept { return {}; }
        static void close(DrmObjectId blob) noexcept { drmModeDestroyPropertyBlob(blob.fd, blob.id); }
    };
    PropertyBlob(int fd, std::uint32_t id) : blob_(DrmObjectId{fd, id}) {}
    UniqueHandle<Traits> blob_;
};

// A DRM framebuffer id (drmModeAddFB2 ...); removed with drmModeRmFB. Removing a framebuffer that
// is on screen turns its CRTC off, which is what should happen when the kiosk exits. Id 0 (no
// framebuffer) owns nothing.
class DrmFramebuffer {
public:
    DrmFramebuffer(int fd, std::uint32_t id) noexcept : framebuffer_(id != 0 ? DrmObjectId{fd, id} : DrmObjectId{}) {}
    [[nodiscard]] std::uint32_t id() const { return framebuffer_.get().id; }

private:
    struct Traits {
        using Value = DrmObjectId;
        static constexpr DrmObjectId null() noexcept { return {}; }
        static void close(DrmObjectId fb) noexcept { drmModeRmFB(fb.fd, fb.id); }
    };
    UniqueHandle<Traits> framebuffer_;
};

}  // namespace mogao
