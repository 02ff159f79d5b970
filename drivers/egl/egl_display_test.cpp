#include "drivers/egl/egl_display.h"

#include <GLES3/gl3.h>
#include <gtest/gtest.h>

#include <string>

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

TEST(EglContext, UnsupportedVersionIsAnError) {
    auto display = EglDisplay::open_surfaceless();
    if (!display) return skip_or_fail_without_egl(display.error().message);
    auto context = EglContext::create(display.value(), EGL_NO_CONFIG_KHR, 9, 0);
    ASSERT_FALSE(context);
    EXPECT_NE(context.error().message.find("eglCreateContext(GLES 9.0)"), std::string::npos)
        << context.error().message;
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
