// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/tag_bitmap.h"

#include <apriltag.h>

#include <gtest/gtest.h>

#include <stdexcept>

namespace mogao {
namespace {

TEST(TagBitmap, Tag36h11HasWhiteThenBlackRingAndItsCodeInside) {
    const TagFamily family("tag36h11");
    const TagBitmap b = make_tag_bitmap(family, 17);
    ASSERT_EQ(b.cells, 10);
    ASSERT_EQ(b.border_cells, 8);
    for (int i = 0; i < 10; ++i) {
        EXPECT_EQ(b.at(i, 0), 255);
        EXPECT_EQ(b.at(i, 9), 255);
        EXPECT_EQ(b.at(0, i), 255);
        EXPECT_EQ(b.at(9, i), 255);
    }
    for (int i = 1; i < 9; ++i) {
        EXPECT_EQ(b.at(i, 1), 0);
        EXPECT_EQ(b.at(i, 8), 0);
        EXPECT_EQ(b.at(1, i), 0);
        EXPECT_EQ(b.at(8, i), 0);
    }
    // Reading the data cells back in AprilTag's bit order gives the family's code.
    const apriltag_family_t& f = *family.get();
    std::uint64_t code = 0;
    for (std::uint32_t i = 0; i < f.nbits; ++i) {
        code =
            (code << 1) | (b.at(static_cast<int>(f.bit_x[i]) + 1, static_cast<int>(f.bit_y[i]) + 1) == 255 ? 1U : 0U);
    }
    EXPECT_EQ(code, f.codes[17]);
}

TEST(TagBitmap, DifferentIdsDifferAndBadIdsAreRefused) {
    const TagFamily family("tag36h11");
    EXPECT_NE(make_tag_bitmap(family, 0).pixels, make_tag_bitmap(family, 1).pixels);
    EXPECT_NO_THROW((void)make_tag_bitmap(family, 586));
    try {
        (void)make_tag_bitmap(family, 587);
        FAIL() << "expected invalid_argument";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("outside [0, 587)"), std::string::npos) << e.what();
    }
    EXPECT_THROW((void)make_tag_bitmap(family, -1), std::invalid_argument);
}

TEST(TagFamily, UnknownNameListsTheKnownOnes) {
    try {
        TagFamily f("tag99h1");
        FAIL() << "expected invalid_argument";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("tag99h1"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("tag36h11"), std::string::npos);
    }
    TagFamily a("tag25h9");
    TagFamily b = std::move(a);
    EXPECT_EQ(b.code_count(), 35);
}

}  // namespace
}  // namespace mogao
