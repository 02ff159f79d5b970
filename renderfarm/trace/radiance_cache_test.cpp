// SPDX-License-Identifier: Apache-2.0
// The radiance cache's hash grid (radiance_cache.h): cells, level of detail, merge order, bad input.
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "renderfarm/trace/radiance_cache.h"

namespace mogao {
namespace {

const Eigen::Vector3f kUp(0.0f, 1.0f, 0.0f);

TEST(RadianceCache, RefusesBadOptionsNamingThem) {
    RadianceCacheOptions o;
    o.base_cell_m = 0.0f;
    EXPECT_THROW(
        {
            try {
                RadianceCache c(o);
            } catch (const std::invalid_argument& e) {
                EXPECT_NE(std::string(e.what()).find("base_cell_m"), std::string::npos);
                throw;
            }
        },
        std::invalid_argument);
    o = {};
    o.slots_log2 = 40;
    EXPECT_THROW(RadianceCache{o}, std::invalid_argument);
    o = {};
    o.train_one_in = 0;
    EXPECT_THROW(RadianceCache{o}, std::invalid_argument);
    o = {};
    o.visibility_min_samples = 13;  // more than the 12 outcomes a cell keeps
    EXPECT_THROW(RadianceCache{o}, std::invalid_argument);
    o = {};
    o.visibility_recheck_one_in = 0;
    EXPECT_THROW(RadianceCache{o}, std::invalid_argument);
}

TEST(RadianceCache, CellsGrowWithTheRayConeInPowersOfTwo) {
    RadianceCache cache;  // base 2 mm, 4 footprints
    EXPECT_FLOAT_EQ(cache.cell_size(0.0f), 0.002f);
    EXPECT_FLOAT_EQ(cache.cell_size(0.0005f), 0.002f);
    EXPECT_FLOAT_EQ(cache.cell_size(0.001f), 0.004f);   // 4 mm wanted: exactly level 1
    EXPECT_FLOAT_EQ(cache.cell_size(0.0011f), 0.008f);  // 4.4 mm wanted: level 2
    EXPECT_GE(cache.cell_size(0.01f), 0.04f);
}

TEST(RadianceCache, KeysSeparateCellsLevelsAndNormalOctants) {
    RadianceCache cache;
    const float cone = 0.001f;  // 4 mm cells
    const Eigen::Vector3d p(1.0011, 0.0, -2.0011);
    EXPECT_EQ(cache.key(p, kUp, cone), cache.key(p + Eigen::Vector3d(0.001, 0.0, 0.001), kUp, cone));
    EXPECT_NE(cache.key(p, kUp, cone), cache.key(p + Eigen::Vector3d(0.004, 0.0, 0.0), kUp, cone));
    EXPECT_NE(cache.key(p, kUp, cone), cache.key(p, -kUp, cone));
    EXPECT_NE(cache.key(p, kUp, cone), cache.key(p, kUp, 0.01f));  // another level
    EXPECT_NE(cache.key(p, kUp, cone), 0u);
}

TEST(RadianceCache, LookupIsTheMeanOfCommittedEstimatesOnly) {
    RadianceCache cache;
    const std::uint64_t k = cache.key({0.5, 0.0, 0.5}, kUp, 0.0f);
    Eigen::Vector3f w;
    EXPECT_FALSE(cache.lookup(k, w));
    const std::vector<CacheDeposit> d = {{k, 0, {1.0f, 2.0f, 3.0f}}, {k, 1, {3.0f, 2.0f, 1.0f}}};
    cache.deposit(d);
    EXPECT_FALSE(cache.lookup(k, w)) << "deposits are not visible before commit()";
    cache.commit();
    ASSERT_TRUE(cache.lookup(k, w));
    EXPECT_TRUE(w.isApprox(Eigen::Vector3f(2.0f, 2.0f, 2.0f)));
    EXPECT_EQ(cache.cells(), 1u);
    cache.clear();
    EXPECT_FALSE(cache.lookup(k, w));
    EXPECT_EQ(cache.cells(), 0u);
}

TEST(RadianceCache, NonFiniteAndNegativeEstimatesAreDroppedNotMerged) {
    RadianceCache cache;
    const std::uint64_t k = cache.key({0.0, 0.0, 0.0}, kUp, 0.0f);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const std::vector<CacheDeposit> d = {
        {k, 0, {nan, 1.0f, 1.0f}}, {k, 1, {-1.0f, 1.0f, 1.0f}}, {k, 2, {0.5f, 0.5f, 0.5f}}};
    cache.deposit(d);
    cache.commit();
    Eigen::Vector3f w;
    ASSERT_TRUE(cache.lookup(k, w));
    EXPECT_TRUE(w.isApprox(Eigen::Vector3f::Constant(0.5f)));
    EXPECT_EQ(cache.dropped(), 2u);
}

TEST(RadianceCache, TheWindowForgetsOldEstimatesExponentially) {
    RadianceCacheOptions o;
    o.max_samples = 4;
    RadianceCache cache(o);
    const std::uint64_t k = cache.key({0.0, 0.0, 0.0}, kUp, 0.0f);
    for (int i = 0; i < 40; ++i) {
        const std::vector<CacheDeposit> d = {{k, 0, Eigen::Vector3f::Zero()}};
        cache.deposit(d);
        cache.commit();
    }
    for (int i = 0; i < 40; ++i) {
        const std::vector<CacheDeposit> d = {{k, 0, Eigen::Vector3f::Ones()}};
        cache.deposit(d);
        cache.commit();
    }
    Eigen::Vector3f w;
    ASSERT_TRUE(cache.lookup(k, w));
    EXPECT_GT(w.x(), 0.99f) << "a 4-sample window must have forgotten the 40 zeros";
}

TEST(RadianceCache, MergedContentDoesNotDependOnTheOrderOfDeposits) {
    RadianceCache a;
    RadianceCache b;
    std::vector<CacheDeposit> all;
    for (int i = 0; i < 500; ++i) {
        const Eigen::Vector3d p(0.001 * (i % 7), 0.0, 0.001 * (i % 5));
        all.push_back({a.key(p, kUp, 0.0f), static_cast<std::uint64_t>(i),
                       Eigen::Vector3f(0.1f * static_cast<float>(i % 13), 0.3f, 1.0f / static_cast<float>(i + 1))});
    }
    a.deposit(all);
    std::vector<CacheDeposit> second(all.begin() + 250, all.end());
    std::vector<CacheDeposit> first(all.begin(), all.begin() + 250);
    b.deposit(second);  // another thread finished first
    b.deposit(first);
    a.commit();
    b.commit();
    for (const CacheDeposit& d : all) {
        Eigen::Vector3f wa;
        Eigen::Vector3f wb;
        ASSERT_TRUE(a.lookup(d.key, wa));
        ASSERT_TRUE(b.lookup(d.key, wb));
        EXPECT_EQ(wa, wb);  // bit-identical
    }
}

TEST(RadianceCache, AFullTableDropsCellsInsteadOfGrowing) {
    RadianceCacheOptions o;
    o.slots_log2 = 8;  // 256 slots
    RadianceCache cache(o);
    std::vector<CacheDeposit> d;
    for (int i = 0; i < 1000; ++i)
        d.push_back({cache.key({0.01 * i, 0.0, 0.0}, kUp, 0.0f), 0, Eigen::Vector3f::Ones()});
    cache.deposit(d);
    cache.commit();
    EXPECT_LE(cache.cells(), 256u);
    EXPECT_GE(cache.dropped(), 1000u - 256u);
}

// A farm serves for months: the queue must not keep the storage of its largest frame ever, or a
// render rank's memory steps up to it and stays there.
TEST(RadianceCache, TheQueueGivesBackTheStorageOfALargeFrame) {
    RadianceCache cache;
    const auto frame = [&](int estimates) {
        std::vector<CacheDeposit> d;
        for (int i = 0; i < estimates; ++i)
            d.push_back({cache.key({0.01 * i, 0.0, 0.0}, kUp, 0.0f), std::uint64_t(i), Eigen::Vector3f::Ones()});
        cache.deposit(d);
        cache.commit();
    };
    frame(100000);
    ASSERT_GE(cache.queue_capacity(), 100000u);
    frame(1000);
    EXPECT_LE(cache.queue_capacity(), 2000u) << "a small frame after a large one";
    frame(1500);
    const std::size_t kept = cache.queue_capacity();
    frame(1200);
    EXPECT_EQ(cache.queue_capacity(), kept) << "frames of about the same size reuse the storage";
}

// Shadow-ray outcomes of one pixel: light group g unoccluded (visible) or occluded (blocked).
CacheDeposit outcome(std::uint64_t key, std::uint64_t order, int group, bool visible) {
    CacheDeposit d{key, order, Eigen::Vector3f::Zero(), false};
    (visible ? d.rays_visible : d.rays_blocked) = static_cast<std::uint8_t>(1u << group);
    return d;
}

TEST(RadianceCache, ACellKnowsALightOnlyAfterEnoughAgreeingRays) {
    RadianceCache cache;  // 8 agreeing outcomes
    const std::uint64_t k = cache.key({0.2, 0.0, 0.2}, kUp, 0.0f);
    std::vector<CacheDeposit> d;
    for (std::uint64_t i = 0; i < 7; ++i) d.push_back(outcome(k, i, 0, true));
    d.push_back(outcome(k, 7, 3, false));
    cache.deposit(d);
    cache.commit();
    EXPECT_EQ(cache.visibility(k).visible, 0) << "7 rays are not enough";
    EXPECT_EQ(cache.visibility(k).blocked, 0);
    Eigen::Vector3f w;
    EXPECT_FALSE(cache.lookup(k, w)) << "shadow-ray outcomes carry no radiance";

    d = {outcome(k, 8, 0, true)};
    cache.deposit(d);
    cache.commit();
    EXPECT_EQ(cache.visibility(k).visible, 1) << "the 8th agreeing ray makes light 0 known visible";

    d = {outcome(k, 9, 0, false)};  // one occluded ray: a shadow edge crosses the cell
    cache.deposit(d);
    cache.commit();
    EXPECT_EQ(cache.visibility(k).visible, 0);
    EXPECT_EQ(cache.visibility(k).blocked, 0);
    d.clear();
    for (std::uint64_t i = 10; i < 16; ++i) d.push_back(outcome(k, i, 0, false));
    cache.deposit(d);
    cache.commit();
    EXPECT_EQ(cache.visibility(k).blocked, 0) << "7 occluded after a visible one: the last 8 still disagree";
    d = {outcome(k, 16, 0, false)};
    cache.deposit(d);
    cache.commit();
    EXPECT_EQ(cache.visibility(k).blocked, 1);
}

TEST(RadianceCache, APixelWithBothOutcomesForALightLeavesItUnknown) {
    RadianceCache cache;
    const std::uint64_t k = cache.key({0.4, 0.0, 0.4}, kUp, 0.0f);
    std::vector<CacheDeposit> d;
    for (std::uint64_t i = 0; i < 12; ++i) {
        CacheDeposit both{k, i, Eigen::Vector3f::Zero(), false, 0x04, 0x04};  // an area light half hidden
        d.push_back(both);
    }
    cache.deposit(d);
    cache.commit();
    EXPECT_EQ(cache.visibility(k).visible, 0);
    EXPECT_EQ(cache.visibility(k).blocked, 0);
}

TEST(RadianceCache, VisibilityOffNeverKnowsALight) {
    RadianceCacheOptions o;
    o.visibility_min_samples = 0;
    RadianceCache cache(o);
    const std::uint64_t k = cache.key({0.6, 0.0, 0.6}, kUp, 0.0f);
    std::vector<CacheDeposit> d;
    for (std::uint64_t i = 0; i < 20; ++i) d.push_back(outcome(k, i, 1, true));
    cache.deposit(d);
    cache.commit();
    EXPECT_EQ(cache.visibility(k).visible, 0);
}

// A deposit of one estimate of the lights' direct white radiance D, with light 0's outcome.
CacheDeposit direct_estimate(std::uint64_t key, std::uint64_t order, float d, bool light0_visible) {
    CacheDeposit out{key, order, Eigen::Vector3f::Zero(), false};
    (light0_visible ? out.rays_visible : out.rays_blocked) = 1;
    out.direct_white = Eigen::Vector3f(d, 2.0f * d, 3.0f * d);
    out.has_direct = true;
    return out;
}

TEST(RadianceCache, ACellOffersItsDirectLightOnceEveryLightIsSettled) {
    RadianceCache cache;  // 8 agreeing outcomes, 8 estimates of D
    const std::uint64_t k = cache.key({0.8, 0.0, 0.8}, kUp, 0.0f);
    std::vector<CacheDeposit> d;
    for (std::uint64_t i = 0; i < 7; ++i) d.push_back(direct_estimate(k, i, 0.5f + 0.1f * static_cast<float>(i), true));
    cache.deposit(d);
    cache.commit();
    EXPECT_FALSE(cache.direct(k).usable) << "7 estimates, light 0 not yet known";
    EXPECT_TRUE(cache.direct(k).trainable) << "its outcomes agree so far";

    d = {direct_estimate(k, 7, 1.2f, true)};
    cache.deposit(d);
    cache.commit();
    const CellDirect settled = cache.direct(k);
    ASSERT_TRUE(settled.usable) << "light 0 known visible, lights 1-7 never traced from the cell";
    EXPECT_EQ(settled.known.visible, 1);
    EXPECT_NEAR(settled.white.x(), 0.85f, 1e-5f) << "the mean of 0.5, 0.6, ..., 1.2";
    EXPECT_NEAR(settled.white.z(), 3.0f * 0.85f, 1e-5f);

    d = {outcome(k, 8, 2, true)};  // light 2 seen once: learning, not known
    cache.deposit(d);
    cache.commit();
    EXPECT_FALSE(cache.direct(k).usable) << "light 2 is neither known nor untouched";
    EXPECT_TRUE(cache.direct(k).trainable);

    d = {outcome(k, 9, 2, false)};  // light 2 both seen and hidden: a shadow edge crosses the cell
    cache.deposit(d);
    cache.commit();
    EXPECT_FALSE(cache.direct(k).usable);
    EXPECT_FALSE(cache.direct(k).trainable) << "its pixels go on tracing, and teach the cell no D";
}

TEST(RadianceCache, DirectLightFromCellsCanBeTurnedOffAndBadEstimatesAreDropped) {
    RadianceCacheOptions off;
    off.cache_direct = false;
    RadianceCache plain(off);
    RadianceCache cache;
    const std::uint64_t k = cache.key({1.0, 0.0, 1.0}, kUp, 0.0f);
    std::vector<CacheDeposit> d;
    for (std::uint64_t i = 0; i < 8; ++i) d.push_back(direct_estimate(k, i, 1.0f, false));
    d.push_back(direct_estimate(k, 8, -1.0f, false));
    d.push_back(direct_estimate(k, 9, std::numeric_limits<float>::quiet_NaN(), false));
    plain.deposit(d);
    plain.commit();
    cache.deposit(d);
    cache.commit();
    EXPECT_FALSE(plain.direct(k).usable);
    ASSERT_TRUE(cache.direct(k).usable) << "light 0 known blocked by 10 outcomes";
    EXPECT_EQ(cache.direct(k).known.blocked, 1);
    EXPECT_FLOAT_EQ(cache.direct(k).white.x(), 1.0f) << "the negative and NaN estimates were not merged";
    EXPECT_EQ(cache.dropped(), 2u);
}

TEST(RadianceCache, CellLevelIsTheCeilingOfLog2OfTheWantedSize) {
    RadianceCache cache;
    for (float cone = 1e-5f; cone < 10.0f; cone *= 1.37f) {
        const float ratio = 4.0f * cone / 0.002f;
        const int expected = ratio > 1.0f ? static_cast<int>(std::ceil(std::log2(ratio))) : 0;
        EXPECT_EQ(cache.cell_level(cone), expected) << "cone " << cone;
        EXPECT_GE(cache.cell_size(cone), 4.0f * cone * 0.9999f);
    }
    EXPECT_EQ(cache.cell_level(std::numeric_limits<float>::infinity()), 40);
    EXPECT_EQ(cache.cell_level(std::numeric_limits<float>::quiet_NaN()), 0);
}

}  // namespace
}  // namespace mogao
