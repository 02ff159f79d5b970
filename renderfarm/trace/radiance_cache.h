// SPDX-License-Identifier: Apache-2.0
// A world-space cache of the diffuse light that arrives at surfaces, shared by every frame, view
// and session one Renderer draws: a spatial hash grid (Binder, Fricke & Keller, "Fast Path Space
// Filtering by Jittered Spatial Hashing", SIGGRAPH 2018 Talks, and "Massively Parallel Path Space
// Filtering", MCQMC 2020; the same scheme as NVIDIA's SHaRC radiance cache). The scene is static:
// what reaches a surface point does not depend on the eye, so a moving view reuses what earlier
// frames (of any session) learnt there.
//
// What a cell holds: the mean of estimates of the "white radiance" W = E / π at points inside it,
// E the irradiance (scene radiance units x sr) from the part of the light the cache carries
// (cached_packet.h says which: the environment and every bounce; the lights' direct light is
// traced per pixel). A Lambertian surface of diffuse reflectance ρ reflects ρ W.
//
// Cells: keyed by (level, floor(p / size) per axis, octant of the normal). size = base_cell_m x
// 2^level, the smallest such size >= cell_footprints x the ray cone's width at the hit
// (texture_lod.h), so a cell covers about cell_footprints pixels on screen at any distance
// (SHaRC's level of detail by distance). Positions are absolute world metres (double: the
// renderer's rebased hit plus its origin), so cells do not move with the eye.
//
// Bias (this is not an unbiased estimator; docs/renderer.md measures it against the converged
// reference): within a cell the cached light is taken as constant, so its shadows and creases
// blur over a cell; lookups at a jittered position (a random offset within the cell in the
// surface's tangent plane, per pixel and frame: Binder et al.) turn blocks into noise the denoiser
// removes. A cell keeps at most max_samples estimates' weight (an exponential window), so its
// noise stops falling at about 1/sqrt(max_samples) of one estimate's.
//
// Threading: lookup() is const and may run on many threads at once; deposit() may run
// concurrently with lookup() and itself (a pending list under a mutex); commit() must not run
// concurrently with either. commit() merges in a fixed order (by key, then each deposit's
// `order`), so the content does not depend on how a frame was split over threads.
#pragma once

#include <cstddef>
#include <cstdint>
#include <mutex>
#include <span>
#include <vector>

#include <Eigen/Core>

namespace mogao {

struct RadianceCacheOptions {
    float base_cell_m = 0.002f;    // size of a level-0 cell, metres (> 0)
    float cell_footprints = 4.0f;  // a cell's size in ray-cone widths (pixels on screen), > 0
    int max_samples = 256;         // the exponential window's length, >= 1
    int slots_log2 = 20;           // 2^slots_log2 cells at most (28 bytes each, allocated at the first
                                   // estimate: a Renderer that never caches pays nothing), in [8, 26]
    int train_one_in = 16;         // pixels of a cached frame that also train the cache: 1 in N (>= 1)
};

// One estimate for the cell `key`; `order` fixes the merge order (renderer: frame, pixel).
struct CacheDeposit {
    std::uint64_t key = 0;
    std::uint64_t order = 0;
    Eigen::Vector3f white_radiance = Eigen::Vector3f::Zero();
};

class RadianceCache {
public:
    // Throws std::invalid_argument naming the option and its limit.
    explicit RadianceCache(const RadianceCacheOptions& options = {});

    [[nodiscard]] const RadianceCacheOptions& options() const { return options_; }

    // Edge of the cells used for a hit whose ray cone is `cone_width` metres wide (0: level 0).
    [[nodiscard]] float cell_size(float cone_width) const;

    // The cell holding absolute world position `world` (metres) on a surface with unit `normal`,
    // for cells of edge `cell_size(cone_width)`. Never 0 (0 marks an empty slot).
    [[nodiscard]] std::uint64_t key(const Eigen::Vector3d& world, const Eigen::Vector3f& normal,
                                    float cone_width) const;

    // The cell's mean white radiance; false when the cell has no estimate yet.
    [[nodiscard]] bool lookup(std::uint64_t key, Eigen::Vector3f& white_radiance) const;

    // Queues estimates for the next commit(); non-finite or negative ones are dropped (counted).
    void deposit(std::span<const CacheDeposit> deposits);

    // Merges the queued estimates. A cell that finds no free slot within its probe window is
    // dropped (counted): the cache never grows past its slots.
    void commit();

    void clear();

    [[nodiscard]] std::size_t cells() const { return cells_; }
    [[nodiscard]] std::uint64_t dropped() const { return dropped_; }

private:
    struct Slot {
        std::uint64_t key = 0;
        float sum[3] = {0.0f, 0.0f, 0.0f};
        float weight = 0.0f;
    };
    [[nodiscard]] const Slot* find(std::uint64_t key) const;
    Slot* find_or_insert(std::uint64_t key);

    RadianceCacheOptions options_;
    std::vector<Slot> slots_;
    std::size_t cells_ = 0;
    std::uint64_t dropped_ = 0;
    std::mutex pending_mutex_;
    std::vector<CacheDeposit> pending_;
};

}  // namespace mogao
