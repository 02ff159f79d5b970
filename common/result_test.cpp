// SPDX-License-Identifier: Apache-2.0
#include "common/result.h"

#include <gtest/gtest.h>

#include <memory>

namespace mogao {
namespace {

Result<int> parse_positive(int x) {
    if (x <= 0) return make_error(EINVAL, "x must be > 0");
    return x;
}

Status propagate(int x) {
    auto r = parse_positive(x);
    if (!r) return with_context(r.error(), "propagate");
    return {};
}

TEST(Result, HoldsValueOrError) {
    auto ok = parse_positive(3);
    ASSERT_TRUE(ok.ok());
    EXPECT_EQ(ok.value(), 3);
    EXPECT_EQ(ok.code(), 0);

    auto bad = parse_positive(-1);
    ASSERT_FALSE(bad.ok());
    EXPECT_EQ(bad.code(), EINVAL);
    EXPECT_EQ(bad.error().message, "x must be > 0");
    EXPECT_FALSE(bad.status().ok());
}

TEST(Result, HoldsMoveOnlyValues) {
    Result<std::unique_ptr<int>> r = std::make_unique<int>(7);
    ASSERT_TRUE(r);
    std::unique_ptr<int> p = std::move(r).value();
    EXPECT_EQ(*p, 7);
}

TEST(Status, DefaultIsSuccessAndContextKeepsCode) {
    EXPECT_TRUE(Status{}.ok());
    EXPECT_EQ(Status{}.code(), 0);
    const Status s = propagate(0);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.code(), EINVAL);
    EXPECT_EQ(s.error().message, "propagate: x must be > 0");
}

TEST(Status, ErrnoErrorNamesCallAndReason) {
    errno = ENOENT;
    const Error e = errno_error("open(/nope)");
    EXPECT_EQ(e.code, ENOENT);
    EXPECT_EQ(e.message, "open(/nope): No such file or directory");
}

TEST(ResultDeathTest, ValueOfErrorAborts) { EXPECT_DEATH((void)parse_positive(0).value(), "x must be > 0"); }

}  // namespace
}  // namespace mogao
