// SPDX-License-Identifier: Apache-2.0
// LibcameraCapture in a build without libcamera (MOGAO_LIBCAMERA=OFF, or AUTO without the
// libcamera pkg-config module): open() reports it, nothing else is reachable.
#include "drivers/camera/libcamera_capture.h"

namespace mogao {

struct LibcameraCapture::Impl {};

bool libcamera_built_in() noexcept { return false; }

Result<std::string> describe_libcamera_cameras(const std::string& camera_id) {
    return make_error(ENOTSUP, "libcamera " + (camera_id.empty() ? std::string("cameras") : camera_id) +
                                   ": built without libcamera (configure with -DMOGAO_LIBCAMERA=ON and "
                                   "install libcamera-dev)");
}

LibcameraCapture::LibcameraCapture() = default;
LibcameraCapture::~LibcameraCapture() = default;

Result<std::unique_ptr<LibcameraCapture>> LibcameraCapture::open(const LibcameraConfig& config) {
    const std::string which = config.camera_id.empty() ? std::string("first camera") : config.camera_id;
    return make_error(ENOTSUP, "libcamera " + which +
                                   ": built without libcamera (configure with -DMOGAO_LIBCAMERA=ON and "
                                   "install libcamera-dev)");
}

Result<CameraFrame> LibcameraCapture::next_frame() { return make_error(ENOTSUP, "built without libcamera"); }

std::string LibcameraCapture::description() const { return "libcamera (built without libcamera)"; }

}  // namespace mogao
