// SPDX-License-Identifier: Apache-2.0
// RAII for EGL objects: EglDisplay (eglInitialize/eglTerminate), EglContext (a GLES 3 context),
// EglSurface (a window surface, e.g. on a gbm_surface for KMS). Errors are Status/Result
// (common/result.h) with code ENODEV (no such platform/display), EINVAL (bad argument) or EIO
// (EGL call failed; the message names the call and the EGL error, e.g. "EGL_BAD_MATCH").
//
// Lifetimes: an EglContext or EglSurface keeps the raw EGLDisplay handle of the EglDisplay it was
// made from; that EglDisplay must outlive them. Declare the display before its contexts/surfaces.
// All three are move-only UniqueHandle owners (common/unique_handle.h): a moved-from object owns
// nothing and its destructor makes no EGL call.
#pragma once

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <string>
#include <string_view>

#include "common/result.h"
#include "common/unique_handle.h"

namespace mogao {

// Name of an EGL error code, e.g. "EGL_BAD_ALLOC"; "0x3001"-style hex for unknown codes.
[[nodiscard]] std::string egl_error_name(EGLint error);

// An initialised EGL display. Mesa hands out one EGLDisplay per (platform, native display), and
// eglTerminate is not reference-counted without EGL_KHR_display_reference (absent in Mesa 22.3), so
// this class counts live EglDisplay objects per handle process-wide and terminates on the last one:
// two owners of the surfaceless display (a test and a backend, say) do not pull it from each other.
class EglDisplay {
public:
    // Mesa's surfaceless platform (EGL_MESA_platform_surfaceless): no window system, no DRM master;
    // renders into FBOs only. On a machine without a GPU Mesa picks llvmpipe (software).
    // ENODEV when EGL lacks the platform or eglInitialize fails.
    [[nodiscard]] static Result<EglDisplay> open_surfaceless();
    // Any platform display, e.g. (EGL_PLATFORM_GBM_KHR, gbm_device*) for KMS output.
    [[nodiscard]] static Result<EglDisplay> open_platform(EGLenum platform, void* native_display);

    [[nodiscard]] EGLDisplay get() const { return display_.get(); }
    [[nodiscard]] int major_version() const { return major_; }
    [[nodiscard]] int minor_version() const { return minor_; }
    // True when the display's extension string lists `name` (exact token match).
    [[nodiscard]] bool has_extension(std::string_view name) const;

private:
    // Mesa returns one shared handle for every open_platform() call, so owners are counted per
    // handle: close() drops this owner's count and calls eglTerminate on the last one.
    // (UniqueHandle's move assignment releases before it takes, so two owners of the same handle
    // each count once.)
    struct Traits {
        using Value = EGLDisplay;
        static EGLDisplay null() noexcept { return EGL_NO_DISPLAY; }
        static void close(EGLDisplay display) noexcept;
    };
    EglDisplay(EGLDisplay display, EGLint major, EGLint minor) : display_(display), major_(major), minor_(minor) {}
    UniqueHandle<Traits> display_;
    int major_ = 0;
    int minor_ = 0;
};

namespace egl_detail {
// An EGL object with the display it was made on: eglDestroy* needs both, so they move together and
// a moved-from owner holds {EGL_NO_DISPLAY, null}.
struct OnDisplay {
    EGLDisplay display = EGL_NO_DISPLAY;
    void* object = nullptr;  // EGLContext or EGLSurface (both void*; EGL_NO_* are null)
    bool operator==(const OnDisplay&) const = default;
};
}  // namespace egl_detail

// An EGL config for window surfaces with 8-bit RGB, no alpha, GLES 3 renderable, whose
// EGL_NATIVE_VISUAL_ID equals `native_visual_id` (for GBM: the gbm_surface's format, e.g.
// GBM_FORMAT_XRGB8888). ENODEV when the display has none.
[[nodiscard]] Result<EGLConfig> choose_window_config(const EglDisplay& display, EGLint native_visual_id);

// A GLES context (default 3.0: the renderer's shaders are GLSL ES 3.00).
class EglContext {
public:
    // `config`: EGL_NO_CONFIG_KHR for an FBO-only context (needs EGL_KHR_no_config_context and, to
    // be made current without a surface, EGL_KHR_surfaceless_context), or the config of the window
    // surfaces it will draw into (all of them must share it).
    [[nodiscard]] static Result<EglContext> create(const EglDisplay& display, EGLConfig config, int major = 3,
                                                   int minor = 0);

    // Destruction releases the context from this thread if it is current here, then destroys it.
    // GL objects made in it must already be deleted (their owners destroyed while it was current).

    // Makes the context current on the calling thread without a surface (FBO rendering).
    [[nodiscard]] Status make_current() const;
    // Makes the context current on the calling thread drawing to and reading from `surface`.
    [[nodiscard]] Status make_current(EGLSurface surface) const;
    [[nodiscard]] EGLContext get() const { return context_.get().object; }

private:
    struct Traits {
        using Value = egl_detail::OnDisplay;
        static Value null() noexcept { return {}; }
        static void close(Value context) noexcept;
    };
    EglContext(EGLDisplay display, EGLContext context) : context_({display, context}) {}
    UniqueHandle<Traits> context_;
};

// A window surface; for KMS the native window is a gbm_surface* (drivers/kms/gbm_objects.h).
class EglSurface {
public:
    [[nodiscard]] static Result<EglSurface> create_window(const EglDisplay& display, EGLConfig config,
                                                          void* native_window);
    // Destruction unbinds the current context first if it draws to this surface on this thread.

    // eglSwapBuffers: the back buffer becomes the front buffer (for GBM: lockable with
    // gbm_surface_lock_front_buffer). The surface must be current on this thread.
    [[nodiscard]] Status swap_buffers() const;
    [[nodiscard]] EGLSurface get() const { return surface_.get().object; }

private:
    struct Traits {
        using Value = egl_detail::OnDisplay;
        static Value null() noexcept { return {}; }
        static void close(Value surface) noexcept;
    };
    EglSurface(EGLDisplay display, EGLSurface surface) : surface_({display, surface}) {}
    UniqueHandle<Traits> surface_;
};

}  // namespace mogao
