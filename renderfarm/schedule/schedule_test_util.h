// SPDX-License-Identifier: Apache-2.0
// Test-only helpers shared by the schedule stage's *_test.cpp files.
#pragma once

#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "renderfarm/schedule/load_balancer.h"

namespace mogao::test {

// Every rect is well formed and inside the image (empty ones included), and every pixel of the
// image is in exactly one rect of exactly one rank.
inline void expect_tiles_image_exactly_once(const Assignment& a, ImageSize size, int ranks) {
    ASSERT_EQ(a.rects.size(), static_cast<std::size_t>(ranks));
    ASSERT_EQ(a.predicted_cost.size(), static_cast<std::size_t>(ranks));
    std::vector<std::uint8_t> count(static_cast<std::size_t>(size.pixel_count()), 0);
    for (std::size_t r = 0; r < a.rects.size(); ++r) {
        for (const PixelRect& rect : a.rects[r]) {
            ASSERT_TRUE(rect.x0 >= 0 && rect.x0 <= rect.x1 && rect.x1 <= size.width && rect.y0 >= 0 &&
                        rect.y0 <= rect.y1 && rect.y1 <= size.height)
                << "rank " << r << " rect [" << rect.x0 << "," << rect.x1 << ")x[" << rect.y0 << "," << rect.y1 << ")";
            for (int y = rect.y0; y < rect.y1; ++y) {
                for (int x = rect.x0; x < rect.x1; ++x) {
                    auto& c = count[static_cast<std::size_t>(y) * static_cast<std::size_t>(size.width) +
                                    static_cast<std::size_t>(x)];
                    c = static_cast<std::uint8_t>(c < 255 ? c + 1 : c);
                }
            }
        }
    }
    std::int64_t wrong = 0;
    std::size_t first_wrong = 0;
    for (std::size_t i = count.size(); i-- > 0;) {
        if (count[i] != 1) {
            ++wrong;
            first_wrong = i;
        }
    }
    EXPECT_EQ(wrong, 0) << "first pixel covered != 1 times: x=" << first_wrong % static_cast<std::size_t>(size.width)
                        << " y=" << first_wrong / static_cast<std::size_t>(size.width) << " ("
                        << int{count[first_wrong]} << " times)";
}

}  // namespace mogao::test
