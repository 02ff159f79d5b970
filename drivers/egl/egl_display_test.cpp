// SPDX-License-Identifier: Apache-2.0
#include "drivers/egl/egl_display.h"

#include <GLES3/gl3.h>
#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <type_traits>
#include <utility>

#include "drivers/egl/egl_test_support.h"

namespace mogao {
namespace {

using mogao::testing::skip_or_fail_without_egl;

TEST(EglDisplay, SurfacelessInitialisesWithSurfacelessContexts) {
    auto display = EglDisplay::open_surfaceless();
    if (!display) return skip_or_fail_without_egl(display.error().message);
    EXPECT_GE(display->major_version() * 10 + display->minor_version(), 14);
    EXPECT_TRUE(display->has_extension("EGL_KHR_surfaceless_context"));
    EXPECT_FALSE(display->has_extension("EGL_KHR_surfaceless"));  // token match, not prefix
}

TEST(EglDisplay, SecondOwnerKeepsDisplayAliveWhenFirstIsDestroyed) {
    auto first = EglDisplay::open_surfaceless();
    if (!first) return skip_or_fail_without_egl(first.error().message);
    auto second = EglDisplay::open_surfaceless();
    ASSERT_TRUE(second) << second.error().message;
    ASSERT_EQ(first->get(), second->get());  // Mesa hands out one handle: the case being tested
    { EglDisplay dropped = std::move(first.value()); }
    auto context = EglContext::create(second.value(), EGL_NO_CONFIG_KHR);
    ASSERT_TRUE(context) << context.error().message;
    ASSERT_TRUE(context->make_current().ok());
    EXPECT_NE(glGetString(GL_VERSION), nullptr);
}

TEST(EglContext, IsGles3AndIsReleasedOnDestruction) {
    auto display = EglDisplay::open_surfaceless();
    if (!display) return skip_or_fail_without_egl(display.error().message);
    {
        auto context = EglContext::create(display.value(), EGL_NO_CONFIG_KHR);
        ASSERT_TRUE(context) << context.error().message;
        ASSERT_TRUE(context->make_current().ok());
        EXPECT_EQ(eglGetCurrentContext(), context->get());
        const std::string version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
        EXPECT_EQ(version.rfind("OpenGL ES 3", 0), 0u) << version;
    }
    EXPECT_EQ(eglGetCurrentContext(), EGL_NO_CONTEXT);
}

static_assert(!std::is_copy_constructible_v<EglDisplay> && std::is_nothrow_move_constructible_v<EglDisplay> &&
              std::is_nothrow_move_assignable_v<EglDisplay>);
static_assert(!std::is_copy_constructible_v<EglContext> && std::is_nothrow_move_constructible_v<EglContext> &&
              std::is_nothrow_move_assignable_v<EglContext>);
static_assert(!std::is_copy_constructible_v<EglSurface> && std::is_nothrow_move_constructible_v<EglSurface> &&
              std::is_nothrow_move_assignable_v<EglSurface>);

// eglQueryString needs an initialised display: NULL (EGL_NOT_INITIALIZED) once it is terminated.
bool initialised(EGLDisplay display) { return eglQueryString(display, EGL_VENDOR) != nullptr; }

TEST(EglDisplay, MovesCountAsOneOwnerAndTheLastOwnerTerminates) {
    auto opened = EglDisplay::open_surfaceless();
    if (!opened) return skip_or_fail_without_egl(opened.error().message);
    const EGLDisplay handle = opened->get();
    std::optional<EglDisplay> source(std::move(opened).value());
    EglDisplay target = std::move(*source);
    EXPECT_EQ(source->get(), EGL_NO_DISPLAY);  // NOLINT(bugprone-use-after-move)
    EXPECT_EQ(target.get(), handle);
    source.reset();  // a moved-from owner must not drop the count
    EXPECT_TRUE(initialised(handle));

    // Assignment drops the replaced owner (the same handle: count 2 -> 1) and keeps the new one.
    auto second = EglDisplay::open_surfaceless();
    ASSERT_TRUE(second) << second.error().message;
    target = std::move(second).value();
    EXPECT_TRUE(initialised(handle));
    { EglDisplay last = std::move(target); }
    EXPECT_FALSE(initialised(handle)) << "the last owner did not eglTerminate (an owner was counted twice)";
}

// eglQueryContext fails with EGL_BAD_CONTEXT for a destroyed context.
bool context_alive(EGLDisplay display, EGLContext context) {
    EGLint id = 0;
    return eglQueryContext(display, context, EGL_CONFIG_ID, &id) == EGL_TRUE;
}

TEST(EglContext, MoveLeavesTheSourceEmptyAndTheLastOwnerDestroysOnce) {
    auto display = EglDisplay::open_surfaceless();
    if (!display) return skip_or_fail_without_egl(display.error().message);
    auto created = EglContext::create(display.value(), EGL_NO_CONFIG_KHR);
    ASSERT_TRUE(created) << created.error().message;
    const EGLContext handle = created->get();

    std::optional<EglContext> source(std::move(created).value());
    EglContext target = std::move(*source);
    EXPECT_EQ(source->get(), EGL_NO_CONTEXT);  // NOLINT(bugprone-use-after-move)
    EXPECT_EQ(source->make_current().code(), EINVAL);
    source.reset();
    EXPECT_TRUE(context_alive(display->get(), handle)) << "destroying the moved-from owner destroyed the context";
    ASSERT_TRUE(target.make_current().ok());
    EXPECT_NE(glGetString(GL_VERSION), nullptr);

    // Assignment destroys the replaced context (released first: it is current here).
    auto other = EglContext::create(display.value(), EGL_NO_CONFIG_KHR);
    ASSERT_TRUE(other) << other.error().message;
    const EGLContext other_handle = other->get();
    target = std::move(other).value();
    EXPECT_EQ(eglGetCurrentContext(), EGL_NO_CONTEXT);
    EXPECT_FALSE(context_alive(display->get(), handle));
    EXPECT_TRUE(context_alive(display->get(), other_handle));
    { EglContext last = std::move(target); }
    EXPECT_FALSE(context_alive(display->get(), other_handle));
}

TEST(EglContext, UnsupportedVersionIsAnError) {
    auto display = EglDisplay::open_surfaceless();
    if (!display) return skip_or_fail_without_egl(display.error().message);
    auto context = EglContext::create(display.value(), EGL_NO_CONFIG_KHR, 9, 0);
    ASSERT_FALSE(context);
    EXPECT_NE(context.error().message.find("eglCreateContext(GLES 9.0)"), std::string::npos) << context.error().message;
}

TEST(EglConfig, SurfacelessDisplayHasNoWindowConfig) {
    auto display = EglDisplay::open_surfaceless();
    if (!display) return skip_or_fail_without_egl(display.error().message);
    auto config = choose_window_config(display.value(), 0x34325258 /* XRGB8888 */);
    ASSERT_FALSE(config);
    EXPECT_EQ(config.code(), ENODEV);
}

TEST(EglErrorName, NamesKnownAndUnknownCodes) {
    EXPECT_EQ(egl_error_name(EGL_BAD_MATCH), "EGL_BAD_MATCH");
    EXPECT_EQ(egl_error_name(0x1234), "0x1234");
}

}  // namespace
}  // namespace mogao
