// SPDX-License-Identifier: Apache-2.0
// What a KMS plane scans out now, read back from the kernel: the framebuffer attached to the plane
// (DRM_IOCTL_MODE_GETPLANE), its buffer object (DRM_IOCTL_MODE_GETFB2), mapped read-only through
// the dumb-buffer mmap offset (DRM_IOCTL_MODE_MAP_DUMB) and copied out as RGB8.
//
// Why: the one way to see, without a camera, what a projector is given -- the kernel's scanout
// buffer, after the flip, not the image the renderer meant to draw. `mogao-calibrate --outputs kms
// --camera rig:FILE` films it with the virtual rig's camera (kiosk/calibrate/rig_camera.h), which is
// how the appliance image's QEMU test runs the whole on-site calibration through virtio-gpu.
//
// Needs DRM master or CAP_SYS_ADMIN (GETFB2 returns buffer handles only to them) and a driver that
// maps the buffer through MAP_DUMB: virtio-gpu, vkms and the software (kms_swrast, dumb-buffer) GBM
// path do; drivers whose scanout buffers are tiled or in VRAM may refuse (the error says so).
// Formats: DRM_FORMAT_XRGB8888 and ARGB8888 (the kiosk's, drivers/kms/kms_backend.cpp); others are
// EOPNOTSUPP naming the fourcc.
// Pixels: row-major, top row first, (R, G, B) per pixel -- the framebuffer's 8-bit codes unchanged
// (sRGB-encoded as the renderer wrote them); the alpha/X byte is dropped.
// Errors (common/result.h): ENODATA (the plane shows no framebuffer), EACCES (no buffer handle: not
// DRM master), EOPNOTSUPP (another format, or a tiled buffer: the modifier is named), the kernel's
// errno otherwise; every
// message names the plane and the framebuffer.
#pragma once

#include <cstdint>

#include "common/image.h"
#include "common/result.h"
#include "drivers/kms/drm_device.h"

namespace mogao {

[[nodiscard]] Result<Rgb8Image> read_scanout(const DrmDevice& drm, std::uint32_t plane_id);

// Converts one row of little-endian 32-bit XRGB8888 words (bytes B, G, R, X in memory) to RGB8.
// `src` holds 4 * width bytes, `dst` 3 * width. Public for its unit test.
void xrgb8888_row_to_rgb8(const std::uint8_t* src, std::uint8_t* dst, int width);

}  // namespace mogao
