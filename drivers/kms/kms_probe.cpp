// SPDX-License-Identifier: Apache-2.0
// mogao-kms-probe: what a technician needs to know about the card before the kiosk runs: the
// driver, each connector (state, modes, possible CRTCs), CRTCs, planes, and which outputs the
// kiosk would light. With --test-pattern-s SECONDS it lights them with the test pattern through
// the same KMS backend and warp/blend renderer as the kiosk.
// Exit codes: 0 ok, 1 failure, 2 bad command line, 77 no DRM device.
#include <poll.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "common/program_cli.h"
#include "drivers/egl/test_pattern.h"
#include "drivers/kms/drm_device.h"
#include "drivers/kms/kms_backend.h"
#include "drivers/kms/kms_layout.h"

namespace {

using namespace mogao;
using DrmVersionPtr = UniquePtr<drmVersion, &drmFreeVersion>;

const char* connection_text(drmModeConnection c) {
    switch (c) {
        case DRM_MODE_CONNECTED:
            return "connected";
        case DRM_MODE_DISCONNECTED:
            return "disconnected";
        default:
            return "unknown";
    }
}

const char* plane_type_text(std::uint64_t type) {
    switch (type) {
        case DRM_PLANE_TYPE_PRIMARY:
            return "primary";
        case DRM_PLANE_TYPE_CURSOR:
            return "cursor";
        default:
            return "overlay";
    }
}

int list(const DrmDevice& drm) {
    if (DrmVersionPtr v{drmGetVersion(drm.fd())}) {
        std::printf("%s: driver %s %d.%d.%d (%s)\n", drm.path().c_str(), v->name, v->version_major, v->version_minor,
                    v->version_patchlevel, v->desc);
    }
    auto res = drm.resources();
    if (!res) return std::fprintf(stderr, "%s\n", res.error().message.c_str()), 1;
    std::printf("connectors:\n");
    for (int i = 0; i < (*res)->count_connectors; ++i) {
        auto c = drm.connector((*res)->connectors[i]);
        if (!c) return std::fprintf(stderr, "%s\n", c.error().message.c_str()), 1;
        std::uint32_t crtcs = 0;
        for (int e = 0; e < (*c)->count_encoders; ++e) {
            if (auto enc = drm.encoder((*c)->encoders[e])) crtcs |= (*enc)->possible_crtcs;
        }
        std::printf("  %-12s id %u %s, %dx%d mm, possible CRTCs 0x%x\n", connector_name(**c).c_str(),
                    (*c)->connector_id, connection_text((*c)->connection), (*c)->mmWidth, (*c)->mmHeight, crtcs);
        const std::span<const drmModeModeInfo> modes((*c)->modes, static_cast<std::size_t>((*c)->count_modes));
        const auto chosen = pick_mode(modes);
        for (std::size_t m = 0; m < modes.size(); ++m) {
            std::printf("    %c %ux%u @ %.2f Hz%s\n", chosen && *chosen == m ? '*' : ' ', modes[m].hdisplay,
                        modes[m].vdisplay, refresh_hz(modes[m]),
                        (modes[m].type & DRM_MODE_TYPE_PREFERRED) != 0 ? " (preferred)" : "");
        }
    }
    std::printf("CRTCs:\n");
    for (int i = 0; i < (*res)->count_crtcs; ++i) {
        auto crtc = drm.crtc((*res)->crtcs[i]);
        if (!crtc) return std::fprintf(stderr, "%s\n", crtc.error().message.c_str()), 1;
        if ((*crtc)->mode_valid != 0) {
            std::printf("  id %u (index %d) active %ux%u @ %.2f Hz, fb %u\n", (*crtc)->crtc_id, i,
                        (*crtc)->mode.hdisplay, (*crtc)->mode.vdisplay, refresh_hz((*crtc)->mode), (*crtc)->buffer_id);
        } else {
            std::printf("  id %u (index %d) off\n", (*crtc)->crtc_id, i);
        }
    }
    std::printf("planes:\n");
    if (auto planes = drm.plane_resources()) {
        for (std::uint32_t i = 0; i < (*planes)->count_planes; ++i) {
            auto plane = drm.plane((*planes)->planes[i]);
            if (!plane) continue;
            auto props = PropertyMap::query(drm.fd(), (*plane)->plane_id, DRM_MODE_OBJECT_PLANE);
            const std::uint64_t type = props && props->value("type") ? *props->value("type") : DRM_PLANE_TYPE_OVERLAY;
            std::printf("  id %u %-7s possible CRTCs 0x%x, %u formats\n", (*plane)->plane_id, plane_type_text(type),
                        (*plane)->possible_crtcs, (*plane)->count_formats);
        }
    }
    auto plans = plan_outputs(drm);
    if (!plans) return std::fprintf(stderr, "%s\n", plans.error().message.c_str()), 1;
    std::printf("outputs the kiosk would light:%s\n", plans->empty() ? " none" : "");
    for (const auto& p : *plans) {
        std::printf("  %s -> CRTC %u, plane %u, %ux%u @ %.2f Hz\n", p.name.c_str(), p.crtc_id, p.plane_id,
                    p.mode.hdisplay, p.mode.vdisplay, refresh_hz(p.mode));
    }
    return 0;
}

// Lights every output with the test pattern for `seconds`, flipping as fast as the display goes.
int light(const std::filesystem::path& device, double seconds) {
    auto created = KmsOutputBackend::create({device});
    if (!created) return std::fprintf(stderr, "%s\n", created.error().message.c_str()), 1;
    OutputBackend& backend = **created;
    ProjectorRenderer& renderer = backend.renderer();
    std::vector<Rgb8Image> patterns;
    for (const auto& out : backend.outputs()) {
        if (auto p = renderer.add_projector(identity_calibration(out.name, out.size)); !p) {
            return std::fprintf(stderr, "%s\n", p.error().message.c_str()), 1;
        }
        patterns.push_back(make_test_pattern(out.size));
    }
    std::vector<long> frames(backend.outputs().size(), 0);
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
        for (std::size_t i = 0; i < backend.outputs().size(); ++i) {
            if (!backend.ready(i)) continue;
            Status s = renderer.set_content(patterns[i]);
            if (s) s = backend.begin_frame(i);
            if (s) s = renderer.draw(i);
            if (s) s = backend.present(i);
            if (!s) return std::fprintf(stderr, "%s\n", s.error().message.c_str()), 1;
            ++frames[i];
        }
        pollfd pfd{backend.event_fd(), POLLIN, 0};
        if (::poll(&pfd, 1, 100) > 0) {
            if (auto done = backend.dispatch_events(); !done) {
                return std::fprintf(stderr, "%s\n", done.error().message.c_str()), 1;
            }
        }
    }
    for (std::size_t i = 0; i < frames.size(); ++i) {
        std::printf("%s: %ld frames in %.1f s\n", backend.outputs()[i].name.c_str(), frames[i], seconds);
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"List DRM/KMS connectors, modes, CRTCs and planes; optionally light the outputs"};
    mogao::cli::prepare(app, "mogao-kms-probe");
    std::string device;
    double seconds = 0;
    // The same text as mogao-calibrate's --kms-device (one text per name, docs/cli.md).
    app.add_option("--kms-device", device,
                   "DRM card node /dev/dri/cardN (default: mogao-calibrate the first with a connected connector, "
                   "mogao-kms-probe every card)")
        ->check(CLI::ExistingFile);
    app.add_option("--test-pattern-s", seconds, "light the outputs with the test pattern for this many seconds")
        ->check(CLI::Range(0.0, 86400.0));
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return mogao::cli::exit_status(app, e);  // prints help or the error; 2 = bad command line
    }

    std::vector<std::filesystem::path> cards;
    if (!device.empty()) cards.emplace_back(device);
    else cards = list_drm_cards();
    if (cards.empty()) {
        std::fprintf(stderr, "no DRM device; the image test (image_qemu_boot) runs this inside QEMU with virtio-gpu\n");
        return 77;
    }
    int rc = 0;
    for (const auto& card : cards) {
        auto drm = DrmDevice::open(card);
        if (!drm) {
            std::fprintf(stderr, "%s\n", drm.error().message.c_str());
            rc = 1;
            continue;
        }
        if (auto s = drm->enable_client_caps(true); !s) std::fprintf(stderr, "%s\n", s.error().message.c_str());
        rc = std::max(rc, list(*drm));
    }
    if (rc == 0 && seconds > 0) rc = light(device, seconds);
    return rc;
}
