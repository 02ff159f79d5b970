// SPDX-License-Identifier: Apache-2.0
#include "drivers/egl/gl_objects.h"

#include <GLES3/gl3.h>
#include <gtest/gtest.h>

#include <optional>
#include <type_traits>
#include <utility>

#include "drivers/egl/egl_test_support.h"

namespace mogao {
namespace {

using GlObjects = mogao::testing::GlTest;

static_assert(!std::is_copy_constructible_v<GlTexture> && std::is_nothrow_move_constructible_v<GlTexture> &&
              std::is_nothrow_move_assignable_v<GlTexture>);

// glIsTexture is true only for a name that is bound once and not yet deleted.
GlTexture bound_texture() {
    GlTexture texture = make_texture();
    glBindTexture(GL_TEXTURE_2D, texture.get());
    glBindTexture(GL_TEXTURE_2D, 0);
    return texture;
}

TEST_F(GlObjects, MoveLeavesTheSourceEmptyAndTheLastOwnerDeletesOnce) {
    std::optional<GlTexture> source(bound_texture());
    const GLuint name = source->get();
    ASSERT_NE(name, 0u);
    ASSERT_EQ(glIsTexture(name), GL_TRUE);

    GlTexture target = std::move(*source);
    EXPECT_FALSE(source->valid());  // NOLINT(bugprone-use-after-move)
    EXPECT_EQ(source->get(), 0u);
    source.reset();
    EXPECT_EQ(glIsTexture(name), GL_TRUE) << "destroying the moved-from owner deleted the texture";
    EXPECT_EQ(target.get(), name);

    target.reset();
    EXPECT_FALSE(target.valid());
    EXPECT_EQ(glIsTexture(name), GL_FALSE);
    EXPECT_TRUE(gl_check("texture moves").ok());
}

TEST_F(GlObjects, AssignmentDeletesTheReplacedName) {
    GlTexture a = bound_texture();
    GlTexture b = bound_texture();
    const GLuint old_name = a.get();
    const GLuint new_name = b.get();
    a = std::move(b);
    EXPECT_EQ(glIsTexture(old_name), GL_FALSE);
    EXPECT_EQ(glIsTexture(new_name), GL_TRUE);
    EXPECT_EQ(a.get(), new_name);
    EXPECT_FALSE(b.valid());  // NOLINT(bugprone-use-after-move)

    // A render target moves as a whole: both of its names survive the source.
    auto target = make_render_target({8, 4});
    ASSERT_TRUE(target) << target.error().message;
    const GLuint fbo = target->fbo.get();
    const GLuint color = target->color.get();
    {
        GlRenderTarget moved = std::move(target).value();
        EXPECT_EQ(moved.fbo.get(), fbo);
        EXPECT_EQ(glIsFramebuffer(fbo), GL_TRUE);
        EXPECT_EQ(glIsRenderbuffer(color), GL_TRUE);
    }
    EXPECT_EQ(glIsFramebuffer(fbo), GL_FALSE);
    EXPECT_EQ(glIsRenderbuffer(color), GL_FALSE);
    EXPECT_TRUE(gl_check("render target moves").ok());
}

}  // namespace
}  // namespace mogao
