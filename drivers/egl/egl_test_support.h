// SPDX-License-Identifier: Apache-2.0
// Test-only: a GoogleTest fixture with a surfaceless EGL display and a current GLES 3.0 context.
// Without EGL the tests are skipped with the reason, unless MOGAO_REQUIRE_EGL is set (CI sets it
// on machines that have Mesa), in which case they fail.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>
#include <string>

#include "drivers/egl/egl_display.h"

namespace mogao::testing {

inline void skip_or_fail_without_egl(const std::string& reason) {
    if (std::getenv("MOGAO_REQUIRE_EGL") != nullptr) {
        FAIL() << "MOGAO_REQUIRE_EGL is set but EGL is unusable: " << reason;
    }
    GTEST_SKIP() << "no usable surfaceless EGL (" << reason
                 << "); install libegl-mesa0 and libgl1-mesa-dri, or set MOGAO_REQUIRE_EGL=1 to fail";
}

class GlTest : public ::testing::Test {
protected:
    void SetUp() override {
        auto display = EglDisplay::open_surfaceless();
        if (!display) return skip_or_fail_without_egl(display.error().message);
        display_.emplace(std::move(display.value()));
        auto context = EglContext::create(*display_, EGL_NO_CONFIG_KHR);
        if (!context) return skip_or_fail_without_egl(context.error().message);
        context_.emplace(std::move(context.value()));
        if (auto s = context_->make_current(); !s) return skip_or_fail_without_egl(s.error().message);
    }
    void TearDown() override {
        context_.reset();
        display_.reset();
    }

    std::optional<EglDisplay> display_;
    std::optional<EglContext> context_;
};

}  // namespace mogao::testing
