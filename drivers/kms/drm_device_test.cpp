// SPDX-License-Identifier: Apache-2.0
#include "drivers/kms/drm_device.h"

#include <dlfcn.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cerrno>
#include <fstream>
#include <map>
#include <optional>
#include <type_traits>
#include <utility>

// Counting stand-ins for the libdrm calls the KMS object owners make: this test binary's own
// definitions take precedence over libdrm's, so the owners' destroy calls can be counted without
// a DRM device. Calls on kFakeFd are recorded; any other fd goes to libdrm (RTLD_NEXT).
namespace {
constexpr int kFakeFd = 1 << 20;  // above any fd this process opens
std::map<std::uint32_t, int>& rmfb_calls() {
    static std::map<std::uint32_t, int> calls;
    return calls;
}
std::map<std::uint32_t, int>& destroy_blob_calls() {
    static std::map<std::uint32_t, int> calls;
    return calls;
}
std::uint32_t next_blob_id = 100;

template <typename Fn>
Fn real(const char* name) {
    return reinterpret_cast<Fn>(dlsym(RTLD_NEXT, name));
}
}  // namespace

int drmModeRmFB(int fd, uint32_t bufferId) {
    if (fd != kFakeFd) return real<int (*)(int, uint32_t)>("drmModeRmFB")(fd, bufferId);
    ++rmfb_calls()[bufferId];
    return 0;
}

int drmModeCreatePropertyBlob(int fd, const void* data, size_t size, uint32_t* id) {
    if (fd != kFakeFd) {
        return real<int (*)(int, const void*, size_t, uint32_t*)>("drmModeCreatePropertyBlob")(fd, data, size, id);
    }
    *id = next_blob_id++;
    return 0;
}

int drmModeDestroyPropertyBlob(int fd, uint32_t id) {
    if (fd != kFakeFd) return real<int (*)(int, uint32_t)>("drmModeDestroyPropertyBlob")(fd, id);
    ++destroy_blob_calls()[id];
    return 0;
}

namespace mogao {
namespace {

static_assert(!std::is_copy_constructible_v<PropertyBlob> && std::is_nothrow_move_constructible_v<PropertyBlob> &&
              std::is_nothrow_move_assignable_v<PropertyBlob>);
static_assert(!std::is_copy_constructible_v<DrmFramebuffer> && std::is_nothrow_move_constructible_v<DrmFramebuffer> &&
              std::is_nothrow_move_assignable_v<DrmFramebuffer>);

TEST(DrmFramebuffer, MoveLeavesTheSourceEmptyAndTheLastOwnerRemovesOnce) {
    rmfb_calls().clear();
    {
        std::optional<DrmFramebuffer> source(std::in_place, kFakeFd, 7u);
        DrmFramebuffer target = std::move(*source);
        EXPECT_EQ(source->id(), 0u);  // NOLINT(bugprone-use-after-move)
        EXPECT_EQ(target.id(), 7u);
        source.reset();
        EXPECT_TRUE(rmfb_calls().empty()) << "destroying the moved-from framebuffer removed it";

        DrmFramebuffer other(kFakeFd, 8u);
        target = std::move(other);  // removes 7, takes 8
        EXPECT_EQ((std::map<std::uint32_t, int>{{7u, 1}}), rmfb_calls());
        EXPECT_EQ(target.id(), 8u);
        DrmFramebuffer none(kFakeFd, 0u);  // id 0 owns nothing
    }
    EXPECT_EQ((std::map<std::uint32_t, int>{{7u, 1}, {8u, 1}}), rmfb_calls());
}

TEST(PropertyBlob, MoveLeavesTheSourceEmptyAndTheLastOwnerDestroysOnce) {
    destroy_blob_calls().clear();
    const int mode = 42;
    auto first = PropertyBlob::create(kFakeFd, &mode, sizeof mode);
    auto second = PropertyBlob::create(kFakeFd, &mode, sizeof mode);
    ASSERT_TRUE(first && second);
    const std::uint32_t first_id = first->id();
    const std::uint32_t second_id = second->id();
    ASSERT_NE(first_id, 0u);
    ASSERT_NE(first_id, second_id);
    {
        std::optional<PropertyBlob> source(std::move(first).value());
        PropertyBlob target = std::move(*source);
        EXPECT_EQ(source->id(), 0u);  // NOLINT(bugprone-use-after-move)
        source.reset();
        EXPECT_TRUE(destroy_blob_calls().empty());
        target = std::move(second).value();
        EXPECT_EQ((std::map<std::uint32_t, int>{{first_id, 1}}), destroy_blob_calls());
        EXPECT_EQ(target.id(), second_id);
    }
    EXPECT_EQ((std::map<std::uint32_t, int>{{first_id, 1}, {second_id, 1}}), destroy_blob_calls());
}

TEST(DrmDevice, MissingNodeIsENOENT) {
    auto d = DrmDevice::open("/nonexistent/dri/card0");
    ASSERT_FALSE(d);
    EXPECT_EQ(d.code(), ENOENT);
    EXPECT_NE(d.error().message.find("/nonexistent/dri/card0"), std::string::npos);
}

TEST(DrmDevice, NonKmsNodeIsENODEV) {
    auto d = DrmDevice::open("/dev/null");
    ASSERT_FALSE(d);
    EXPECT_EQ(d.code(), ENODEV);
    EXPECT_NE(d.error().message.find("not a KMS device"), std::string::npos) << d.error().message;
}

TEST(ListDrmCards, SortsCardsByNumberAndIgnoresOtherNodes) {
    const auto dir = std::filesystem::temp_directory_path() / ("mogao-dri-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    for (const char* name : {"card10", "card2", "renderD128", "card0", "cardX", "card"})
        std::ofstream(dir / name) << "";
    const auto cards = list_drm_cards(dir);
    ASSERT_EQ(cards.size(), 3u);
    EXPECT_EQ(cards[0].filename(), "card0");
    EXPECT_EQ(cards[1].filename(), "card2");
    EXPECT_EQ(cards[2].filename(), "card10");
    std::filesystem::remove_all(dir);
    EXPECT_TRUE(list_drm_cards(dir).empty());
}

TEST(ConnectorName, UsesKernelTypeNameAndTypeId) {
    drmModeConnector c{};
    c.connector_type = DRM_MODE_CONNECTOR_HDMIA;
    c.connector_type_id = 2;
    EXPECT_EQ(connector_name(c), "HDMI-A-2");
    c.connector_type = DRM_MODE_CONNECTOR_VIRTUAL;
    c.connector_type_id = 1;
    EXPECT_EQ(connector_name(c), "Virtual-1");
}

}  // namespace
}  // namespace mogao
