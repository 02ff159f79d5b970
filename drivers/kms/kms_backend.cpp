// SPDX-License-Identifier: Apache-2.0
#include "drivers/kms/kms_backend.h"

#include <drm_fourcc.h>

#include <GLES3/gl3.h>

#include <time.h>

#include <algorithm>
#include <string>

#include "drivers/egl/gl_objects.h"
#include "drivers/kms/kms_layout.h"
#include "drivers/kms/scanout_reader.h"

namespace mogao {

// Property ids used in atomic requests, looked up once per output.
struct KmsProps {
    std::uint32_t connector_crtc_id, crtc_mode_id, crtc_active;
    std::uint32_t fb_id, plane_crtc_id, src_x, src_y, src_w, src_h, crtc_x, crtc_y, crtc_w, crtc_h;
};

struct KmsOutputBackend::Output {
    Output(OutputPlan p, KmsProps k, PropertyBlob blob, GbmSurface gbm, EglSurface egl)
        : plan(std::move(p)),
          props(k),
          mode_blob(std::move(blob)),
          gbm_surface(std::move(gbm)),
          egl_surface(std::move(egl)) {}

    OutputPlan plan;
    KmsProps props;
    // Destroyed in reverse: pending/on_screen bos go back to the GBM surface first, then the EGL
    // surface on it, then the surface (destroying its bos and their DRM framebuffers).
    PropertyBlob mode_blob;
    GbmSurface gbm_surface;
    EglSurface egl_surface;
    LockedBo on_screen;  // scanned out now
    LockedBo pending;    // committed, waiting for its flip event
    LockedBo staged;     // drawn and locked, waiting for commit_round()
    std::uint32_t staged_fb = 0;
    std::optional<std::int64_t> presented_ns;  // CLOCK_REALTIME of the latest completed present
    bool modeset_done = false;
    bool begun = false;
    bool flipped = false;  // set by the page-flip handler, collected by dispatch_events()
};

namespace {

constexpr std::uint32_t kFormat = GBM_FORMAT_XRGB8888;  // == DRM_FORMAT_XRGB8888

bool plane_supports(const drmModePlane& plane, std::uint32_t format) {
    return std::find(plane.formats, plane.formats + plane.count_formats, format) != plane.formats + plane.count_formats;
}

Result<KmsProps> lookup_props(int fd, const OutputPlan& plan) {
    auto connector = PropertyMap::query(fd, plan.connector_id, DRM_MODE_OBJECT_CONNECTOR);
    if (!connector) return connector.error();
    auto crtc = PropertyMap::query(fd, plan.crtc_id, DRM_MODE_OBJECT_CRTC);
    if (!crtc) return crtc.error();
    auto plane = PropertyMap::query(fd, plan.plane_id, DRM_MODE_OBJECT_PLANE);
    if (!plane) return plane.error();
    KmsProps k{};
    const struct {
        const PropertyMap* map;
        const char* name;
        std::uint32_t* id;
    } wanted[] = {{&*connector, "CRTC_ID", &k.connector_crtc_id},
                  {&*crtc, "MODE_ID", &k.crtc_mode_id},
                  {&*crtc, "ACTIVE", &k.crtc_active},
                  {&*plane, "FB_ID", &k.fb_id},
                  {&*plane, "CRTC_ID", &k.plane_crtc_id},
                  {&*plane, "SRC_X", &k.src_x},
                  {&*plane, "SRC_Y", &k.src_y},
                  {&*plane, "SRC_W", &k.src_w},
                  {&*plane, "SRC_H", &k.src_h},
                  {&*plane, "CRTC_X", &k.crtc_x},
                  {&*plane, "CRTC_Y", &k.crtc_y},
                  {&*plane, "CRTC_W", &k.crtc_w},
                  {&*plane, "CRTC_H", &k.crtc_h}};
    for (const auto& w : wanted) {
        auto id = w.map->id(w.name);
        if (!id) return id.error();
        *w.id = *id;
    }
    return k;
}

// Adds output `o`'s plane (and, for its first frame, its connector and CRTC mode) to `req`.
bool add_output(drmModeAtomicReq* req, const KmsOutputBackend::Output& o, std::uint32_t fb_id, bool modeset) {
    const KmsProps& p = o.props;
    const OutputPlan& plan = o.plan;
    bool ok = true;
    const auto add = [&](std::uint32_t object, std::uint32_t prop, std::uint64_t value) {
        ok = ok && drmModeAtomicAddProperty(req, object, prop, value) >= 0;
    };
    if (modeset) {
        add(plan.connector_id, p.connector_crtc_id, plan.crtc_id);
        add(plan.crtc_id, p.crtc_mode_id, o.mode_blob.id());
        add(plan.crtc_id, p.crtc_active, 1);
    }
    const std::uint64_t w = plan.mode.hdisplay;
    const std::uint64_t h = plan.mode.vdisplay;
    add(plan.plane_id, p.fb_id, fb_id);
    add(plan.plane_id, p.plane_crtc_id, plan.crtc_id);
    add(plan.plane_id, p.src_x, 0);
    add(plan.plane_id, p.src_y, 0);
    add(plan.plane_id, p.src_w, w << 16);  // source rectangle in 16.16 fixed point
    add(plan.plane_id, p.src_h, h << 16);
    add(plan.plane_id, p.crtc_x, 0);
    add(plan.plane_id, p.crtc_y, 0);
    add(plan.plane_id, p.crtc_w, w);
    add(plan.plane_id, p.crtc_h, h);
    return ok;
}

std::int64_t clock_ns(clockid_t clock) {
    timespec ts{};
    clock_gettime(clock, &ts);
    return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// One atomic commit of every output in `round` (each holding its staged bo). When any of them has
// not been modeset yet, the commit is a blocking modeset of all of them (once, at start-up);
// otherwise a non-blocking flip whose completion is one page-flip event per CRTC, carrying
// `user_data`.
Status commit(int fd, const std::vector<KmsOutputBackend::Output*>& round, void* user_data, bool* modeset) {
    DrmAtomicRequest req(drmModeAtomicAlloc());
    if (!req) return make_error(ENOMEM, "drmModeAtomicAlloc");
    *modeset = std::any_of(round.begin(), round.end(), [](const auto* o) { return !o->modeset_done; });
    std::string names;
    for (const auto* o : round) {
        if (!add_output(req.get(), *o, o->staged_fb, !o->modeset_done)) {
            return make_error(ENOMEM, "drmModeAtomicAddProperty");
        }
        names += (names.empty() ? "" : ", ") + o->plan.name;
    }
    const std::uint32_t flags =
        *modeset ? DRM_MODE_ATOMIC_ALLOW_MODESET : DRM_MODE_ATOMIC_NONBLOCK | DRM_MODE_PAGE_FLIP_EVENT;
    if (drmModeAtomicCommit(fd, req.get(), flags, *modeset ? nullptr : user_data) != 0) {
        Error e = errno_error(std::string(*modeset ? "modeset" : "page flip") + " commit on " + names);
        if (e.code == EACCES || e.code == EPERM) e.message += " (not DRM master: is a compositor running?)";
        return e;
    }
    return {};
}

// page_flip_handler2: one call per CRTC of a commit; `sec`/`usec` is when the new frame started
// scanning out (the kernel's vblank timestamp, CLOCK_MONOTONIC: DRM_CAP_TIMESTAMP_MONOTONIC is 1 on
// every kernel since 3.x), kept as CLOCK_REALTIME for the kiosk's motion-to-photon.
void on_page_flip(int /*fd*/, unsigned /*sequence*/, unsigned sec, unsigned usec, unsigned crtc, void* user_data) {
    auto* outputs = static_cast<std::vector<std::unique_ptr<KmsOutputBackend::Output>>*>(user_data);
    const std::int64_t flip_mono = static_cast<std::int64_t>(sec) * 1'000'000'000 + std::int64_t{usec} * 1000;
    const std::int64_t realtime = clock_ns(CLOCK_REALTIME) - (clock_ns(CLOCK_MONOTONIC) - flip_mono);
    for (auto& o : *outputs) {
        if (o->plan.crtc_id != crtc || !o->pending.valid()) continue;
        o->on_screen = std::move(o->pending);  // releases the bo that was on screen until now
        o->flipped = true;
        o->presented_ns = realtime;
    }
}

Result<DrmDevice> open_card(const std::filesystem::path& path, std::vector<OutputPlan>& plans) {
    auto drm = DrmDevice::open(path);
    if (!drm) return drm.error();
    if (auto s = drm->enable_client_caps(true); !s) return s.error();
    auto planned = plan_outputs(*drm);
    if (!planned) return with_context(planned.error(), path.string());
    if (planned->empty()) return make_error(ENODEV, path.string() + ": no connected output with a free CRTC and plane");
    plans = std::move(planned.value());
    return drm;
}

}  // namespace

Result<std::vector<OutputPlan>> plan_outputs(const DrmDevice& drm) {
    auto res = drm.resources();
    if (!res) return res.error();
    std::vector<OutputPlan> candidates;
    std::vector<std::uint32_t> masks;
    for (int i = 0; i < (*res)->count_connectors; ++i) {
        auto connector = drm.connector((*res)->connectors[i]);
        if (!connector) return connector.error();
        const drmModeConnector& c = **connector;
        if (c.connection != DRM_MODE_CONNECTED || c.count_modes <= 0) continue;
        std::uint32_t mask = 0;
        for (int e = 0; e < c.count_encoders; ++e) {
            if (auto encoder = drm.encoder(c.encoders[e])) mask |= (*encoder)->possible_crtcs;
        }
        const std::span<const drmModeModeInfo> modes(c.modes, static_cast<std::size_t>(c.count_modes));
        OutputPlan plan;
        plan.connector_id = c.connector_id;
        plan.name = connector_name(c);
        plan.mode = modes[*pick_mode(modes)];
        candidates.push_back(std::move(plan));
        masks.push_back(mask);
    }
    const auto crtc_of = assign_crtcs(masks, (*res)->count_crtcs);

    auto plane_res = drm.plane_resources();
    if (!plane_res) return plane_res.error();
    std::vector<PlaneCandidate> planes;
    for (std::uint32_t i = 0; i < (*plane_res)->count_planes; ++i) {
        auto plane = drm.plane((*plane_res)->planes[i]);
        if (!plane) return plane.error();
        auto props = PropertyMap::query(drm.fd(), (*plane)->plane_id, DRM_MODE_OBJECT_PLANE);
        if (!props) return props.error();
        auto type = props->value("type");
        planes.push_back({(*plane)->plane_id, (*plane)->possible_crtcs, type ? *type : DRM_PLANE_TYPE_OVERLAY,
                          plane_supports(**plane, kFormat)});
    }
    std::vector<bool> taken(planes.size(), false);
    std::vector<OutputPlan> plans;
    for (std::size_t c = 0; c < candidates.size(); ++c) {
        if (!crtc_of[c]) continue;
        const auto plane = pick_plane(planes, *crtc_of[c], taken);
        if (!plane) continue;
        taken[*plane] = true;
        candidates[c].crtc_id = (*res)->crtcs[*crtc_of[c]];
        candidates[c].plane_id = planes[*plane].id;
        plans.push_back(std::move(candidates[c]));
    }
    return plans;
}

Result<std::unique_ptr<KmsOutputBackend>> KmsOutputBackend::create(const KmsOptions& options) {
    std::vector<OutputPlan> plans;
    std::optional<DrmDevice> drm;
    if (!options.device.empty()) {
        auto opened = open_card(options.device, plans);
        if (!opened) return opened.error();
        drm.emplace(std::move(opened.value()));
    } else {
        const auto cards = list_drm_cards();
        if (cards.empty()) return make_error(ENODEV, "no DRM device (/dev/dri/card*)");
        Error last;
        for (const auto& card : cards) {
            auto opened = open_card(card, plans);
            if (opened) {
                drm.emplace(std::move(opened.value()));
                break;
            }
            last = opened.error();
        }
        if (!drm) return last;
    }
    // Without DRM master every commit fails; say so now rather than at the first frame.
    if (drmIsMaster(drm->fd()) == 0) {
        return make_error(EACCES, drm->path().string() + ": not DRM master (is a compositor running on this card?)");
    }

    auto gbm = GbmDevice::create(drm->fd());
    if (!gbm) return gbm.error();
    auto egl = EglDisplay::open_platform(EGL_PLATFORM_GBM_KHR, gbm->get());
    if (!egl) return with_context(egl.error(), "EGL on GBM");
    auto config = choose_window_config(*egl, static_cast<EGLint>(kFormat));
    if (!config) return config.error();
    auto context = EglContext::create(*egl, *config);
    if (!context) return context.error();

    std::unique_ptr<KmsOutputBackend> backend(new KmsOutputBackend(std::move(*drm), std::move(gbm.value()),
                                                                   std::move(egl.value()), std::move(context.value())));
    const int fd = backend->drm_.fd();
    for (auto& plan : plans) {
        const ImageSize size{plan.mode.hdisplay, plan.mode.vdisplay};
        auto props = lookup_props(fd, plan);
        if (!props) return with_context(props.error(), plan.name);
        auto blob = PropertyBlob::create(fd, &plan.mode, sizeof plan.mode);
        if (!blob) return with_context(blob.error(), plan.name);
        auto gbm_surface = GbmSurface::create(backend->gbm_, size, kFormat, GBM_BO_USE_SCANOUT | GBM_BO_USE_RENDERING);
        if (!gbm_surface) return with_context(gbm_surface.error(), plan.name);
        auto egl_surface = EglSurface::create_window(backend->egl_, *config, gbm_surface->get());
        if (!egl_surface) return with_context(egl_surface.error(), plan.name);
        backend->infos_.push_back({plan.name, size, refresh_hz(plan.mode)});
        backend->outputs_.push_back(std::make_unique<Output>(std::move(plan), *props, std::move(blob.value()),
                                                             std::move(gbm_surface.value()),
                                                             std::move(egl_surface.value())));
    }
    if (auto s = backend->context_.make_current(backend->outputs_.front()->egl_surface.get()); !s) return s.error();
    auto renderer = WarpBlendRenderer::create();
    if (!renderer) return renderer.error();
    backend->renderer_.emplace(std::move(renderer.value()));
    return backend;
}

KmsOutputBackend::KmsOutputBackend(DrmDevice drm, GbmDevice gbm, EglDisplay egl, EglContext context)
    : drm_(std::move(drm)), gbm_(std::move(gbm)), egl_(std::move(egl)), context_(std::move(context)) {}

KmsOutputBackend::~KmsOutputBackend() {
    // The renderer's GL names need the context current; any of its surfaces will do.
    if (renderer_ && !outputs_.empty()) {
        (void)context_.make_current(outputs_.front()->egl_surface.get());
        renderer_.reset();
    }
}

Status KmsOutputBackend::check_index(std::size_t i) const {
    if (i >= outputs_.size()) {
        return make_error(
            EINVAL, "output " + std::to_string(i) + " out of range (have " + std::to_string(outputs_.size()) + ")");
    }
    return {};
}

Result<Rgb8Image> KmsOutputBackend::read_scanout(std::size_t i) const {
    if (auto s = check_index(i); !s) return s.error();
    auto image = mogao::read_scanout(drm_, outputs_[i]->plan.plane_id);
    if (!image) return with_context(image.error(), "output " + outputs_[i]->plan.name);
    return image;
}

bool KmsOutputBackend::ready(std::size_t i) const {
    return i < outputs_.size() && !outputs_[i]->pending.valid() && !outputs_[i]->staged.valid() &&
           outputs_[i]->gbm_surface.has_free_buffers();
}

std::optional<std::int64_t> KmsOutputBackend::presented_ns(std::size_t i) const {
    return i < outputs_.size() ? outputs_[i]->presented_ns : std::nullopt;
}

Status KmsOutputBackend::begin_frame(std::size_t i) {
    if (auto s = check_index(i); !s) return s;
    Output& o = *outputs_[i];
    if (!ready(i)) return make_error(EBUSY, o.plan.name + ": previous frame still waiting for its flip");
    if (auto s = context_.make_current(o.egl_surface.get()); !s) return with_context(s.error(), o.plan.name);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, o.plan.mode.hdisplay, o.plan.mode.vdisplay);
    glDisable(GL_SCISSOR_TEST);
    glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    o.begun = true;
    return gl_check(o.plan.name + ": begin_frame");
}

Status KmsOutputBackend::stage(std::size_t i) {
    if (auto s = check_index(i); !s) return s;
    Output& o = *outputs_[i];
    if (!o.begun) return make_error(EINVAL, o.plan.name + ": present() without begin_frame()");
    o.begun = false;
    // eglSwapBuffers needs the surface current; another output may have been drawn since.
    if (auto s = context_.make_current(o.egl_surface.get()); !s) return with_context(s.error(), o.plan.name);
    if (auto s = o.egl_surface.swap_buffers(); !s) return with_context(s.error(), o.plan.name);
    auto bo = LockedBo::lock_front(o.gbm_surface);
    if (!bo) return with_context(bo.error(), o.plan.name);
    auto fb = framebuffer_for(bo->get(), drm_.fd());
    if (!fb) return with_context(fb.error(), o.plan.name);  // `bo` goes back to the surface
    o.staged = std::move(bo.value());
    o.staged_fb = *fb;
    return {};
}

Status KmsOutputBackend::commit_outputs(const std::vector<Output*>& round) {
    if (round.empty()) return {};
    bool modeset = false;
    Status s = commit(drm_.fd(), round, &outputs_, &modeset);
    const std::int64_t now = clock_ns(CLOCK_REALTIME);
    for (Output* o : round) {
        if (!s) {
            o->staged = LockedBo{};  // back to its surface; the screen keeps what it showed
        } else if (modeset) {
            o->on_screen = std::move(o->staged);
            o->modeset_done = true;
            o->presented_ns = now;
        } else {
            o->pending = std::move(o->staged);
        }
    }
    return s;
}

Status KmsOutputBackend::present(std::size_t i) {
    if (auto s = stage(i); !s) return s;
    return commit_outputs({outputs_[i].get()});
}

Status KmsOutputBackend::commit_round() {
    std::vector<Output*> round;
    for (auto& o : outputs_) {
        if (o->staged.valid()) round.push_back(o.get());
    }
    return commit_outputs(round);
}

Result<std::vector<std::size_t>> KmsOutputBackend::dispatch_events() {
    drmEventContext ev{};
    ev.version = 3;                         // page_flip_handler2
    ev.page_flip_handler2 = &on_page_flip;  // user data: &outputs_ (commit_outputs)
    // The fd is non-blocking: read until the kernel has nothing more (EAGAIN). Bounded, as a
    // 60 Hz flip per output cannot outrun a few reads.
    for (int reads = 0; reads < 64; ++reads) {
        errno = 0;
        if (drmHandleEvent(drm_.fd(), &ev) == 0) continue;
        if (errno == EAGAIN || errno == EWOULDBLOCK) break;
        if (errno == 0) return make_error(EIO, "drmHandleEvent: short read from " + drm_.path().string());
        return errno_error("drmHandleEvent");
    }
    std::vector<std::size_t> completed;
    for (std::size_t i = 0; i < outputs_.size(); ++i) {
        if (std::exchange(outputs_[i]->flipped, false)) completed.push_back(i);
    }
    return completed;
}

}  // namespace mogao
