// SPDX-License-Identifier: Apache-2.0
// KmsOutputBackend: one output per connected connector that gets a CRTC and a plane (several
// projectors on one card), each with a GBM surface and an EGL window surface, all drawn by one
// GLES context and one WarpBlendRenderer.
//
// Per output frame (the non-fence path: llvmpipe/virgl may lack EGL_ANDROID_native_fence_sync):
//   begin_frame   eglMakeCurrent(output's surface), bind framebuffer 0, clear
//   (draw)        renderer().draw(projector)
//   stage         eglSwapBuffers -> gbm_surface_lock_front_buffer -> DRM framebuffer of the bo
//   commit_round  ONE atomic commit carrying the plane of every staged output (drivers/output.h):
//                 first frame:  with ALLOW_MODESET (connector CRTC_ID, CRTC MODE_ID blob + ACTIVE,
//                               plane FB_ID/CRTC_ID/SRC_*/CRTC_*), blocking
//                 later frames: NONBLOCK | PAGE_FLIP_EVENT, so all CRTCs flip in the same commit
//   flip event    (dispatch_events after poll(event_fd()) says POLLIN) one per CRTC of the commit,
//                 matched to its output by CRTC id: the new bo is on screen; the previous one is
//                 released to the GBM surface; the output is ready again; presented_ns() is the
//                 event's timestamp (tv_sec/tv_usec, CLOCK_MONOTONIC, stored as CLOCK_REALTIME).
//   present       stage + a commit of that output alone (probes).
//
// The backend needs DRM master (no other compositor on the card) and the thread that created it.
// Errors: ENODEV (no card / no connected output / no GBM or EGL), EOPNOTSUPP (no atomic KMS),
// EACCES (not DRM master), EBUSY (output not ready), EINVAL (bad index), EIO (EGL/GL).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/image.h"
#include "drivers/egl/egl_display.h"
#include "drivers/egl/warp_blend_renderer.h"
#include "drivers/kms/drm_device.h"
#include "drivers/kms/gbm_objects.h"
#include "drivers/output.h"

namespace mogao {

// What create() will light: one entry per connected connector that got a CRTC and a plane.
struct OutputPlan {
    std::uint32_t connector_id = 0;
    std::string name;        // "HDMI-A-1"
    drmModeModeInfo mode{};  // pick_mode(): preferred, else largest
    std::uint32_t crtc_id = 0;
    std::uint32_t plane_id = 0;
};

// Decides the outputs of `drm` (needs enable_client_caps(true) first for all planes to be
// listed). Connectors that are disconnected, have no modes, or get no CRTC/plane are left out.
[[nodiscard]] Result<std::vector<OutputPlan>> plan_outputs(const DrmDevice& drm);

struct KmsOptions {
    // A /dev/dri/card* node; empty: the first card (by number) with a connected connector.
    std::filesystem::path device;
};

class KmsOutputBackend final : public OutputBackend {
public:
    [[nodiscard]] static Result<std::unique_ptr<KmsOutputBackend>> create(const KmsOptions& options);
    ~KmsOutputBackend() override;
    KmsOutputBackend(const KmsOutputBackend&) = delete;
    KmsOutputBackend& operator=(const KmsOutputBackend&) = delete;

    [[nodiscard]] const std::vector<OutputInfo>& outputs() const override { return infos_; }
    [[nodiscard]] WarpBlendRenderer& renderer() override { return *renderer_; }
    [[nodiscard]] Status begin_frame(std::size_t i) override;
    [[nodiscard]] Status present(std::size_t i) override;
    [[nodiscard]] Status stage(std::size_t i) override;
    [[nodiscard]] Status commit_round() override;
    [[nodiscard]] std::optional<std::int64_t> presented_ns(std::size_t i) const override;
    [[nodiscard]] bool ready(std::size_t i) const override;
    [[nodiscard]] int event_fd() const override { return drm_.fd(); }
    [[nodiscard]] Result<std::vector<std::size_t>> dispatch_events() override;

    [[nodiscard]] const std::filesystem::path& device_path() const { return drm_.path(); }

    // What output `i`'s plane scans out now, read back from the kernel (drivers/kms/scanout_reader.h:
    // the framebuffer after its flip, RGB8 codes as drawn). EINVAL for a bad index; its errors otherwise.
    [[nodiscard]] Result<Rgb8Image> read_scanout(std::size_t i) const;

    struct Output;  // per-connector state (kms_backend.cpp)

private:
    KmsOutputBackend(DrmDevice drm, GbmDevice gbm, EglDisplay egl, EglContext context);
    [[nodiscard]] Status check_index(std::size_t i) const;
    // One atomic commit of `round`'s staged bos; on failure they go back to their surfaces.
    [[nodiscard]] Status commit_outputs(const std::vector<Output*>& round);

    // Declaration order is destruction order reversed: renderer (with the context current), the
    // outputs (locked bos, EGL surfaces, GBM surfaces and with them the DRM framebuffers, mode
    // blobs), the context, the EGL display, the GBM device, and last the DRM fd.
    DrmDevice drm_;
    GbmDevice gbm_;
    EglDisplay egl_;
    EglContext context_;
    std::vector<std::unique_ptr<Output>> outputs_;  // stable addresses: page-flip user data
    std::optional<WarpBlendRenderer> renderer_;
    std::vector<OutputInfo> infos_;
};

}  // namespace mogao
