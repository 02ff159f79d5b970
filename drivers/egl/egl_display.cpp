// SPDX-License-Identifier: Apache-2.0
#include "drivers/egl/egl_display.h"

#include <cstdio>
#include <map>
#include <mutex>
#include <vector>

namespace mogao {
namespace {

// Live EglDisplay objects per EGLDisplay handle (see the class comment for why).
std::mutex& registry_mutex() {
    static std::mutex m;
    return m;
}
std::map<EGLDisplay, int>& registry() {
    static std::map<EGLDisplay, int> counts;
    return counts;
}

Error egl_failure(std::string_view call, int code = EIO) {
    return make_error(code, std::string(call) + " failed: " + egl_error_name(eglGetError()));
}

bool has_token(const char* list, std::string_view name) {
    if (list == nullptr) return false;
    std::string_view rest(list);
    while (!rest.empty()) {
        const auto end = rest.find(' ');
        if (rest.substr(0, end) == name) return true;
        if (end == std::string_view::npos) break;
        rest.remove_prefix(end + 1);
    }
    return false;
}

}  // namespace

std::string egl_error_name(EGLint error) {
    switch (error) {
        case EGL_SUCCESS:
            return "EGL_SUCCESS";
        case EGL_NOT_INITIALIZED:
            return "EGL_NOT_INITIALIZED";
        case EGL_BAD_ACCESS:
            return "EGL_BAD_ACCESS";
        case EGL_BAD_ALLOC:
            return "EGL_BAD_ALLOC";
        case EGL_BAD_ATTRIBUTE:
            return "EGL_BAD_ATTRIBUTE";
        case EGL_BAD_CONFIG:
            return "EGL_BAD_CONFIG";
        case EGL_BAD_CONTEXT:
            return "EGL_BAD_CONTEXT";
        case EGL_BAD_CURRENT_SURFACE:
            return "EGL_BAD_CURRENT_SURFACE";
        case EGL_BAD_DISPLAY:
            return "EGL_BAD_DISPLAY";
        case EGL_BAD_MATCH:
            return "EGL_BAD_MATCH";
        case EGL_BAD_NATIVE_PIXMAP:
            return "EGL_BAD_NATIVE_PIXMAP";
        case EGL_BAD_NATIVE_WINDOW:
            return "EGL_BAD_NATIVE_WINDOW";
        case EGL_BAD_PARAMETER:
            return "EGL_BAD_PARAMETER";
        case EGL_BAD_SURFACE:
            return "EGL_BAD_SURFACE";
        case EGL_CONTEXT_LOST:
            return "EGL_CONTEXT_LOST";
        default: {
            char buf[16];
            std::snprintf(buf, sizeof buf, "0x%04x", static_cast<unsigned>(error));
            return buf;
        }
    }
}

// ---- EglDisplay --------------------------------------------------------------------------------

Result<EglDisplay> EglDisplay::open_surfaceless() {
    if (!has_token(eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS), "EGL_MESA_platform_surfaceless")) {
        return make_error(ENODEV,
                          "EGL has no surfaceless platform (EGL_MESA_platform_surfaceless; "
                          "install libegl-mesa0 and libgl1-mesa-dri)");
    }
    return open_platform(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY);
}

Result<EglDisplay> EglDisplay::open_platform(EGLenum platform, void* native_display) {
    // EGL 1.5 core entry point (libglvnd exports it); Mesa 22.3 implements EGL 1.5.
    EGLDisplay display = eglGetPlatformDisplay(platform, native_display, nullptr);
    if (display == EGL_NO_DISPLAY) return egl_failure("eglGetPlatformDisplay", ENODEV);
    std::lock_guard lock(registry_mutex());
    EGLint major = 0;
    EGLint minor = 0;
    // Re-initialising an initialised display is allowed and returns its version.
    if (eglInitialize(display, &major, &minor) != EGL_TRUE) return egl_failure("eglInitialize", ENODEV);
    ++registry()[display];
    return EglDisplay(display, major, minor);
}

void EglDisplay::Traits::close(EGLDisplay display) noexcept {
    std::lock_guard lock(registry_mutex());
    auto it = registry().find(display);
    if (it != registry().end() && --it->second == 0) {
        registry().erase(it);
        eglTerminate(display);
    }
}

bool EglDisplay::has_extension(std::string_view name) const {
    return has_token(eglQueryString(get(), EGL_EXTENSIONS), name);
}

Result<EGLConfig> choose_window_config(const EglDisplay& display, EGLint native_visual_id) {
    const EGLint attribs[] = {EGL_SURFACE_TYPE,
                              EGL_WINDOW_BIT,
                              EGL_RED_SIZE,
                              8,
                              EGL_GREEN_SIZE,
                              8,
                              EGL_BLUE_SIZE,
                              8,
                              EGL_ALPHA_SIZE,
                              0,
                              EGL_RENDERABLE_TYPE,
                              EGL_OPENGL_ES3_BIT,
                              EGL_NONE};
    EGLint count = 0;
    if (eglChooseConfig(display.get(), attribs, nullptr, 0, &count) != EGL_TRUE) {
        return egl_failure("eglChooseConfig");
    }
    std::vector<EGLConfig> configs(static_cast<std::size_t>(count));
    if (count > 0 && eglChooseConfig(display.get(), attribs, configs.data(), count, &count) != EGL_TRUE) {
        return egl_failure("eglChooseConfig");
    }
    // eglChooseConfig matches sizes as minimums; GBM needs the exact native format, so filter.
    for (EGLConfig config : configs) {
        EGLint id = 0;
        if (eglGetConfigAttrib(display.get(), config, EGL_NATIVE_VISUAL_ID, &id) == EGL_TRUE &&
            id == native_visual_id) {
            return config;
        }
    }
    char buf[64];
    std::snprintf(buf, sizeof buf, "no EGL window config with native visual 0x%08x",
                  static_cast<unsigned>(native_visual_id));
    return make_error(ENODEV, buf);
}

// ---- EglContext --------------------------------------------------------------------------------

Result<EglContext> EglContext::create(const EglDisplay& display, EGLConfig config, int major, int minor) {
    if (config == EGL_NO_CONFIG_KHR && !display.has_extension("EGL_KHR_no_config_context") &&
        !display.has_extension("EGL_MESA_configless_context")) {
        return make_error(ENODEV, "EGL display lacks EGL_KHR_no_config_context");
    }
    if (eglBindAPI(EGL_OPENGL_ES_API) != EGL_TRUE) return egl_failure("eglBindAPI(EGL_OPENGL_ES_API)", ENODEV);
    const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, major, EGL_CONTEXT_MINOR_VERSION, minor, EGL_NONE};
    EGLContext context = eglCreateContext(display.get(), config, EGL_NO_CONTEXT, attribs);
    if (context == EGL_NO_CONTEXT)
        return egl_failure("eglCreateContext(GLES " + std::to_string(major) + "." + std::to_string(minor) + ")");
    return EglContext(display.get(), context);
}

void EglContext::Traits::close(egl_detail::OnDisplay context) noexcept {
    if (eglGetCurrentContext() == context.object) {
        eglMakeCurrent(context.display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    }
    eglDestroyContext(context.display, context.object);
}

Status EglContext::make_current() const { return make_current(EGL_NO_SURFACE); }

Status EglContext::make_current(EGLSurface surface) const {
    if (!context_) return make_error(EINVAL, "make_current on an empty EglContext");
    const egl_detail::OnDisplay c = context_.get();
    if (eglMakeCurrent(c.display, surface, surface, c.object) != EGL_TRUE) return egl_failure("eglMakeCurrent");
    return {};
}

// ---- EglSurface --------------------------------------------------------------------------------

Result<EglSurface> EglSurface::create_window(const EglDisplay& display, EGLConfig config, void* native_window) {
    if (native_window == nullptr) return make_error(EINVAL, "EglSurface::create_window: null native window");
    EGLSurface surface = eglCreatePlatformWindowSurface(display.get(), config, native_window, nullptr);
    if (surface == EGL_NO_SURFACE) return egl_failure("eglCreatePlatformWindowSurface");
    return EglSurface(display.get(), surface);
}

void EglSurface::Traits::close(egl_detail::OnDisplay surface) noexcept {
    // A current surface is only destroyed when released; release it now so the gbm_surface under
    // it can be destroyed right after.
    if (eglGetCurrentSurface(EGL_DRAW) == surface.object || eglGetCurrentSurface(EGL_READ) == surface.object) {
        eglMakeCurrent(surface.display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    }
    eglDestroySurface(surface.display, surface.object);
}

Status EglSurface::swap_buffers() const {
    const egl_detail::OnDisplay s = surface_.get();
    if (eglSwapBuffers(s.display, s.object) != EGL_TRUE) return egl_failure("eglSwapBuffers");
    return {};
}

}  // namespace mogao
