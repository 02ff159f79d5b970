// SPDX-License-Identifier: Apache-2.0
#include "drivers/kms/gbm_objects.h"

#include <dlfcn.h>
#include <gtest/gtest.h>

#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

// Counting stand-ins for the GBM calls the owners make: this test binary's own definitions take
// precedence over libgbm's, so creation and destruction are observable without a DRM device.
// kFakeFd and the fake objects below are recorded; anything else goes to libgbm (RTLD_NEXT).
namespace {
constexpr int kFakeFd = (1 << 20) + 1;  // above any fd this process opens
char fake_device_storage;
char fake_surface_storage[2];
char fake_bo_storage[4];
auto* const fake_device = reinterpret_cast<gbm_device*>(&fake_device_storage);

bool is_fake_surface(const gbm_surface* s) {
    return s == reinterpret_cast<const gbm_surface*>(&fake_surface_storage[0]) ||
           s == reinterpret_cast<const gbm_surface*>(&fake_surface_storage[1]);
}

struct Calls {
    int device_destroyed = 0;
    std::vector<const gbm_surface*> surfaces_destroyed;
    std::vector<const gbm_bo*> bos_released;
    int surfaces_created = 0;
    int bos_locked = 0;
};
Calls calls;

template <typename Fn>
Fn real(const char* name) {
    return reinterpret_cast<Fn>(dlsym(RTLD_NEXT, name));
}
}  // namespace

gbm_device* gbm_create_device(int fd) {
    if (fd != kFakeFd) return real<gbm_device* (*)(int)>("gbm_create_device")(fd);
    return fake_device;
}

void gbm_device_destroy(gbm_device* gbm) {
    if (gbm != fake_device) return real<void (*)(gbm_device*)>("gbm_device_destroy")(gbm);
    ++calls.device_destroyed;
}

gbm_surface* gbm_surface_create(gbm_device* gbm, uint32_t width, uint32_t height, uint32_t format, uint32_t flags) {
    if (gbm != fake_device) {
        return real<gbm_surface* (*)(gbm_device*, uint32_t, uint32_t, uint32_t, uint32_t)>("gbm_surface_create")(
            gbm, width, height, format, flags);
    }
    return reinterpret_cast<gbm_surface*>(&fake_surface_storage[calls.surfaces_created++ % 2]);
}

void gbm_surface_destroy(gbm_surface* surface) {
    if (!is_fake_surface(surface)) return real<void (*)(gbm_surface*)>("gbm_surface_destroy")(surface);
    calls.surfaces_destroyed.push_back(surface);
}

gbm_bo* gbm_surface_lock_front_buffer(gbm_surface* surface) {
    if (!is_fake_surface(surface)) return real<gbm_bo* (*)(gbm_surface*)>("gbm_surface_lock_front_buffer")(surface);
    return reinterpret_cast<gbm_bo*>(&fake_bo_storage[calls.bos_locked++ % 4]);
}

void gbm_surface_release_buffer(gbm_surface* surface, gbm_bo* bo) {
    if (!is_fake_surface(surface)) {
        return real<void (*)(gbm_surface*, gbm_bo*)>("gbm_surface_release_buffer")(surface, bo);
    }
    calls.bos_released.push_back(bo);
}

namespace mogao {
namespace {

static_assert(!std::is_copy_constructible_v<GbmDevice> && std::is_nothrow_move_constructible_v<GbmDevice> &&
              std::is_nothrow_move_assignable_v<GbmDevice>);
static_assert(!std::is_copy_constructible_v<GbmSurface> && std::is_nothrow_move_constructible_v<GbmSurface> &&
              std::is_nothrow_move_assignable_v<GbmSurface>);
static_assert(!std::is_copy_constructible_v<LockedBo> && std::is_nothrow_move_constructible_v<LockedBo> &&
              std::is_nothrow_move_assignable_v<LockedBo>);

TEST(GbmObjects, MovesLeaveSourcesEmptyAndEachObjectIsReleasedOnceByItsLastOwner) {
    calls = {};
    {
        auto created = GbmDevice::create(kFakeFd);
        ASSERT_TRUE(created) << created.error().message;
        std::optional<GbmDevice> device_source(std::move(created).value());
        GbmDevice device = std::move(*device_source);
        EXPECT_EQ(device_source->get(), nullptr);  // NOLINT(bugprone-use-after-move)
        device_source.reset();
        EXPECT_EQ(calls.device_destroyed, 0);

        auto s1 = GbmSurface::create(device, {64, 32}, GBM_FORMAT_XRGB8888, GBM_BO_USE_SCANOUT);
        auto s2 = GbmSurface::create(device, {64, 32}, GBM_FORMAT_XRGB8888, GBM_BO_USE_SCANOUT);
        ASSERT_TRUE(s1 && s2);
        const gbm_surface* first_surface = s1->get();
        const gbm_surface* second_surface = s2->get();
        std::optional<GbmSurface> surface_source(std::move(s1).value());
        GbmSurface surface = std::move(*surface_source);
        EXPECT_EQ(surface_source->get(), nullptr);  // NOLINT(bugprone-use-after-move)
        surface_source.reset();
        EXPECT_TRUE(calls.surfaces_destroyed.empty());
        {
            auto b1 = LockedBo::lock_front(surface);
            auto b2 = LockedBo::lock_front(surface);
            ASSERT_TRUE(b1 && b2);
            const gbm_bo* first_bo = b1->get();
            const gbm_bo* second_bo = b2->get();
            std::optional<LockedBo> bo_source(std::move(b1).value());
            LockedBo bo = std::move(*bo_source);
            EXPECT_FALSE(bo_source->valid());  // NOLINT(bugprone-use-after-move)
            bo_source.reset();
            EXPECT_TRUE(calls.bos_released.empty()) << "destroying a moved-from LockedBo released the buffer";
            bo = std::move(b2).value();  // releases the first buffer, to its surface
            EXPECT_EQ(calls.bos_released, (std::vector<const gbm_bo*>{first_bo}));
            LockedBo empty;
            EXPECT_FALSE(empty.valid());
            bo.reset();
            EXPECT_FALSE(bo.valid());
            EXPECT_EQ(calls.bos_released, (std::vector<const gbm_bo*>{first_bo, second_bo}));
        }
        EXPECT_EQ(calls.bos_released.size(), 2u);

        surface = std::move(s2).value();  // destroys the first surface
        EXPECT_EQ(calls.surfaces_destroyed, (std::vector<const gbm_surface*>{first_surface}));
        EXPECT_EQ(surface.get(), second_surface);
    }
    EXPECT_EQ(calls.surfaces_destroyed.size(), 2u);
    EXPECT_EQ(calls.device_destroyed, 1);
}

}  // namespace
}  // namespace mogao
