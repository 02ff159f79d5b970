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
// Shadow-ray visibility: a cell also keeps, per light group (the light's index in the frame's
// light set, the first kVisibilityGroups lights), the outcomes of the last shadow rays traced from
// inside it (a shift register of up to 12). A cell whose last visibility_min_samples outcomes for a
// light all agree "knows" that light: cached_packet.h adds the light's unshadowed contribution
// (known visible) or nothing (known blocked) without tracing the ray, and still traces one pixel
// in visibility_recheck_one_in so the history stays fresh. A cell that a shadow edge crosses keeps
// a mixed history and every pixel in it traces. The scheme is ours: the cache's own cells reused as
// a visibility cache, in the spirit of estimating a point's visibility from nearby, earlier shadow
// rays (Clarberg & Akenine-Möller, "Exploiting Visibility Correlation in Direct Illumination",
// EGSR 2008, who use it as a control variate instead, and stay unbiased).
// Its bias: a shadow (or a lit patch) smaller than a cell that no recent ray from that cell hit is
// missed until a recheck ray hits it; docs/renderer.md measures it against the converged reference.
//
// Direct light from the cells (RadianceCacheOptions::cache_direct): a cell also keeps the mean of
// estimates of the lights' direct "white radiance" D = E_lights / π (traced per pixel, with the
// shadow rays the cell does not know, at pixels of diffuse materials). Where every light group of
// a cell is known (visible or blocked) or has never had a ray traced from the cell (below its
// horizon, behind its emitter, or casting no shadows), direct(key) says the cell is usable: a
// diffuse pixel there takes ρ D from the cell and evaluates no light (cached_packet.h). A cell that
// a shadow edge crosses keeps a mixed history, is never usable and never trained, so its pixels go
// on evaluating their lights per pixel and shadow edges stay as sharp as the pixels. Its bias, on
// top of the visibility's: the direct light's smooth variation (distance, cosine, an area light's
// extent) is taken as constant over a cell.
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
    float base_cell_m = 0.002f;         // size of a level-0 cell, metres (> 0)
    float cell_footprints = 4.0f;       // a cell's size in ray-cone widths (pixels on screen), > 0
    int max_samples = 256;              // the exponential window's length, >= 1
    int slots_log2 = 20;                // 2^slots_log2 cells at most (56 bytes each, allocated at the first
                                        // estimate: a Renderer that never caches pays nothing), in [8, 26]
    int train_one_in = 16;              // pixels of a cached frame that also train the cache: 1 in N (>= 1)
    int visibility_min_samples = 8;     // agreeing shadow-ray outcomes before a cell knows a light,
                                        // in [0, 12]; 0: every shadow ray is traced
    int visibility_recheck_one_in = 8;  // pixels of a known cell that trace anyway: 1 in N (>= 1)
    bool cache_direct = true;           // cells whose lights are all known keep the lights' direct light
                                        // (see above; needs visibility_min_samples > 0)
};

// Lights whose visibility a cell keeps: the first 8 of the frame's light set (the rest are traced).
inline constexpr int kVisibilityGroups = 8;

// What a cell knows of its lights' visibility: bit g set for light group g.
struct CellVisibility {
    std::uint8_t visible = 0;  // the last visibility_min_samples rays towards g were all unoccluded
    std::uint8_t blocked = 0;  // ... all occluded
};

// What a cell offers a diffuse pixel of its lights' direct light (cache_direct, see above).
struct CellDirect {
    bool usable = false;    // every light group known or untouched, and at least visibility_min_samples
                            // estimates of D merged
    bool trainable = true;  // no light group's recent outcomes disagree (an absent cell: true)
    CellVisibility known;   // as visibility(key)
    Eigen::Vector3f white = Eigen::Vector3f::Zero();  // the mean of D's estimates (when usable)
};

// Everything a cached pixel reads of one cell, from one probe of the table.
struct CellRead {
    bool has_radiance = false;                        // W has an estimate
    Eigen::Vector3f white = Eigen::Vector3f::Zero();  // the mean of W's estimates (when has_radiance)
    CellDirect direct;                                // as direct(key)
};

// One estimate for the cell `key`; `order` fixes the merge order (renderer: frame, pixel).
struct CacheDeposit {
    std::uint64_t key = 0;
    std::uint64_t order = 0;
    Eigen::Vector3f white_radiance = Eigen::Vector3f::Zero();
    bool has_radiance = true;       // false: the deposit carries no estimate of W
    std::uint8_t rays_visible = 0;  // light groups with at least one unoccluded shadow ray traced
    std::uint8_t rays_blocked = 0;  // light groups with at least one occluded shadow ray traced
    Eigen::Vector3f direct_white = Eigen::Vector3f::Zero();  // an estimate of D (when has_direct)
    bool has_direct = false;
};

class RadianceCache {
public:
    // Throws std::invalid_argument naming the option and its limit.
    explicit RadianceCache(const RadianceCacheOptions& options = {});

    [[nodiscard]] const RadianceCacheOptions& options() const { return options_; }

    // Level of the cells used for a hit whose ray cone is `cone_width` metres wide (0: level 0),
    // and their edge base_cell_m x 2^level.
    [[nodiscard]] int cell_level(float cone_width) const;
    [[nodiscard]] float level_size(int level) const;
    [[nodiscard]] float cell_size(float cone_width) const { return level_size(cell_level(cone_width)); }

    // The cell holding absolute world position `world` (metres) on a surface with unit `normal`,
    // for cells of edge `cell_size(cone_width)`. Never 0 (0 marks an empty slot).
    [[nodiscard]] std::uint64_t key(const Eigen::Vector3d& world, const Eigen::Vector3f& normal,
                                    float cone_width) const {
        return key_at_level(world, normal, cell_level(cone_width));
    }
    [[nodiscard]] std::uint64_t key_at_level(const Eigen::Vector3d& world, const Eigen::Vector3f& normal,
                                             int level) const;

    // Hints the cell's home slot into the CPU cache (lookups of a packet's 16 lanes miss it in turn
    // otherwise: the table is far larger than the caches).
    void prefetch(std::uint64_t key) const {
        if (!slots_.empty()) __builtin_prefetch(&slots_[key & (slots_.size() - 1)]);
    }

    // The cell's mean white radiance; false when the cell has no estimate yet.
    [[nodiscard]] bool lookup(std::uint64_t key, Eigen::Vector3f& white_radiance) const;

    // What the cell knows of its lights' visibility (nothing for an absent cell).
    [[nodiscard]] CellVisibility visibility(std::uint64_t key) const;

    // The cell's direct light for a diffuse pixel (never usable with cache_direct off or
    // visibility_min_samples 0).
    [[nodiscard]] CellDirect direct(std::uint64_t key) const;

    // lookup(), visibility() and direct() of one cell at once (one probe of the table).
    [[nodiscard]] CellRead read(std::uint64_t key) const;

    // Queues estimates for the next commit(); non-finite or negative ones are dropped (counted).
    void deposit(std::span<const CacheDeposit> deposits);

    // Merges the queued estimates. A cell that finds no free slot within its probe window is
    // dropped (counted): the cache never grows past its slots. The queue keeps its storage for the
    // next frame unless it holds more than twice what this commit merged: then it shrinks to this
    // commit's size, so one large frame (a still view's, a larger resolution) does not hold its
    // memory for the rest of the farm's life.
    void commit();

    void clear();

    [[nodiscard]] std::size_t cells() const { return cells_; }
    [[nodiscard]] std::uint64_t dropped() const { return dropped_; }
    // Estimates the queue can hold without allocating (its storage, kept between frames).
    [[nodiscard]] std::size_t queue_capacity() const { return pending_.capacity(); }

private:
    struct Slot {
        std::uint64_t key = 0;
        float sum[3] = {0.0f, 0.0f, 0.0f};
        float weight = 0.0f;
        std::uint16_t visibility[kVisibilityGroups] = {};  // per light group: outcome count << 12 | history
        float direct_sum[3] = {0.0f, 0.0f, 0.0f};          // D's estimates (cache_direct)
        float direct_weight = 0.0f;
    };
    [[nodiscard]] CellVisibility known_of(const Slot& s) const;
    [[nodiscard]] CellDirect direct_of(const Slot& s) const;
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
