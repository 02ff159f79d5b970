// SPDX-License-Identifier: Apache-2.0
// Reading back a plane's scanout buffer (scanout_reader.h).
#include "drivers/kms/scanout_reader.h"

#include <drm_fourcc.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "common/mapped_buffer.h"
#include "common/unique_handle.h"

namespace mogao {
namespace {

using DrmFb2 = UniquePtr<drmModeFB2, &drmModeFreeFB2>;

// A GEM buffer handle GETFB2 opened on `fd` for this process: closed (DRM_IOCTL_GEM_CLOSE) once read.
struct GemHandleTraits {
    using Value = DrmObjectId;
    static constexpr DrmObjectId null() noexcept { return {}; }
    static void close(DrmObjectId h) noexcept { drmCloseBufferHandle(h.fd, h.id); }
};
using GemHandle = UniqueHandle<GemHandleTraits>;

std::string fourcc_text(std::uint32_t f) {
    std::string s(4, ' ');
    for (int i = 0; i < 4; ++i) s[static_cast<std::size_t>(i)] = static_cast<char>((f >> (8 * i)) & 0xff);
    return s;
}

}  // namespace

void xrgb8888_row_to_rgb8(const std::uint8_t* src, std::uint8_t* dst, int width) {
    for (int x = 0; x < width; ++x, src += 4, dst += 3) {
        dst[0] = src[2];
        dst[1] = src[1];
        dst[2] = src[0];
    }
}

Result<Rgb8Image> read_scanout(const DrmDevice& drm, std::uint32_t plane_id) {
    const std::string where = "scanout of plane " + std::to_string(plane_id);
    auto plane = drm.plane(plane_id);
    if (!plane) return with_context(plane.error(), where);
    const std::uint32_t fb_id = plane.value()->fb_id;
    if (fb_id == 0) return make_error(ENODATA, where + ": the plane shows no framebuffer");
    const std::string fb_where = where + " (framebuffer " + std::to_string(fb_id) + ")";
    DrmFb2 fb(drmModeGetFB2(drm.fd(), fb_id));
    if (!fb) return errno_error("drmModeGetFB2: " + fb_where);
    // Every distinct handle GETFB2 returned is ours to close, even those of planes we do not read.
    GemHandle handles[4];
    for (int i = 0; i < 4; ++i) {
        bool seen = false;
        for (int j = 0; j < i; ++j) seen = seen || fb->handles[j] == fb->handles[i];
        if (fb->handles[i] != 0 && !seen) handles[i].reset(DrmObjectId{drm.fd(), fb->handles[i]});
    }
    if (fb->pixel_format != DRM_FORMAT_XRGB8888 && fb->pixel_format != DRM_FORMAT_ARGB8888) {
        return make_error(EOPNOTSUPP, fb_where + ": pixel format " + fourcc_text(fb->pixel_format) +
                                          " (only XR24/AR24 are read back)");
    }
    if (fb->modifier != DRM_FORMAT_MOD_LINEAR && fb->modifier != DRM_FORMAT_MOD_INVALID &&
        (fb->flags & DRM_MODE_FB_MODIFIERS) != 0) {
        char modifier[32];
        std::snprintf(modifier, sizeof modifier, "0x%016llx", static_cast<unsigned long long>(fb->modifier));
        return make_error(EOPNOTSUPP, fb_where + ": tiled buffer (modifier " + modifier + ")");
    }
    if (fb->handles[0] == 0) {
        return make_error(EACCES, fb_where + ": no buffer handle (needs DRM master or CAP_SYS_ADMIN)");
    }
    const auto width = static_cast<int>(fb->width);
    const auto height = static_cast<int>(fb->height);
    const std::size_t pitch = fb->pitches[0];
    if (width <= 0 || height <= 0 || pitch < 4 * static_cast<std::size_t>(width)) {
        return make_error(EINVAL, fb_where + ": " + std::to_string(width) + "x" + std::to_string(height) +
                                      " with pitch " + std::to_string(pitch));
    }
    drm_mode_map_dumb map{};
    map.handle = fb->handles[0];
    if (drmIoctl(drm.fd(), DRM_IOCTL_MODE_MAP_DUMB, &map) != 0) {
        return errno_error("DRM_IOCTL_MODE_MAP_DUMB: " + fb_where + " (the driver cannot map its scanout buffer)");
    }
    const std::size_t length = fb->offsets[0] + pitch * static_cast<std::size_t>(height);
    auto mapped = MappedBuffer::map(drm.fd(), length, static_cast<off_t>(map.offset));
    if (!mapped) return with_context(mapped.error(), fb_where);
    Rgb8Image image(ImageSize{width, height});
    const std::uint8_t* base = mapped.value().bytes().data() + fb->offsets[0];
    // A row at a time into cached memory first: scanout buffers are often mapped write-combined, where
    // reading a byte at a time is very slow.
    std::vector<std::uint8_t> row(4 * static_cast<std::size_t>(width));
    for (int y = 0; y < height; ++y) {
        std::memcpy(row.data(), base + pitch * static_cast<std::size_t>(y), row.size());
        xrgb8888_row_to_rgb8(row.data(), image.at(0, y), width);
    }
    return image;
}

}  // namespace mogao
