// SPDX-License-Identifier: Apache-2.0
#include "common/unique_handle.h"

#include <vector>

#include <gtest/gtest.h>

namespace mogao {
namespace {

// Records every value it is asked to close, so each test can check "exactly once, never null".
std::vector<int> g_closed;

struct RecordingTraits {
    using Value = int;
    static constexpr int null() noexcept { return 0; }
    static void close(int v) noexcept { g_closed.push_back(v); }
};
using Handle = UniqueHandle<RecordingTraits>;

TEST(UniqueHandle, ClosesEachOwnedValueExactlyOnceAndNeverNull) {
    g_closed.clear();
    {
        Handle empty;
        EXPECT_FALSE(empty.valid());
        Handle a(7);
        Handle b(std::move(a));
        EXPECT_FALSE(a.valid());  // NOLINT(bugprone-use-after-move): moved-from state is specified
        EXPECT_EQ(b.get(), 7);
        Handle c(9);
        c = std::move(b);  // closes 9, takes 7
        EXPECT_EQ(g_closed, (std::vector<int>{9}));
        EXPECT_EQ(c.get(), 7);
    }
    EXPECT_EQ(g_closed, (std::vector<int>{9, 7}));
}

TEST(UniqueHandle, ReleaseAndResetKeepOwnershipExplicit) {
    g_closed.clear();
    Handle a(3);
    EXPECT_EQ(a.release(), 3);
    EXPECT_FALSE(a);
    a.reset(4);
    a.reset(4);  // the value already owned: kept, not closed
    EXPECT_TRUE(g_closed.empty());
    a.reset(5);
    EXPECT_EQ(g_closed, (std::vector<int>{4}));
    a.reset();
    EXPECT_EQ(g_closed, (std::vector<int>{4, 5}));
}

int g_freed = 0;
void free_int(int* p) {
    ++g_freed;
    delete p;
}

TEST(UniquePtr, CallsTheLibraryFreeFunctionOnce) {
    g_freed = 0;
    { UniquePtr<int, &free_int> p(new int(1)); }
    { UniquePtr<int, &free_int> none; }
    EXPECT_EQ(g_freed, 1);
}

}  // namespace
}  // namespace mogao
