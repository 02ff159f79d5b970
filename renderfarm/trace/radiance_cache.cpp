// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/trace/radiance_cache.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "renderfarm/trace/rng.h"

namespace mogao {
namespace {

constexpr int kProbe = 16;     // slots tried after the home slot (linear probing)
constexpr int kMaxLevel = 40;  // 2^40 x base: far beyond any scene

void require(bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("RadianceCacheOptions." + what);
}

constexpr int kHistoryBits = 12;  // Slot::visibility: outcomes kept per light group
constexpr std::uint16_t kHistoryMask = (1u << kHistoryBits) - 1u;

// Appends one shadow-ray outcome (1: unoccluded) to a light group's history.
std::uint16_t push_outcome(std::uint16_t state, bool visible) {
    const int count = std::min(kHistoryBits, (state >> kHistoryBits) + 1);
    const auto history = static_cast<std::uint16_t>(((state << 1) | (visible ? 1u : 0u)) & kHistoryMask);
    return static_cast<std::uint16_t>((count << kHistoryBits) | history);
}

// Adds one estimate to a running sum of at most `window` estimates' weight (an exponential
// window: older estimates weigh less).
void merge(float (&sum)[3], float& weight, const Eigen::Vector3f& estimate, float window) {
    if (weight + 1.0f > window) {
        const float keep = (window - 1.0f) / weight;
        for (float& c : sum) c *= keep;
        weight = window - 1.0f;
    }
    for (int c = 0; c < 3; ++c) sum[c] += estimate[c];
    weight += 1.0f;
}

std::uint64_t cell_coordinate(double position, double size) {
    return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(position / size)));
}

}  // namespace

RadianceCache::RadianceCache(const RadianceCacheOptions& options) : options_(options) {
    require(options.base_cell_m > 0.0f && std::isfinite(options.base_cell_m), "base_cell_m must be > 0");
    require(options.cell_footprints > 0.0f && std::isfinite(options.cell_footprints), "cell_footprints must be > 0");
    require(options.max_samples >= 1, "max_samples must be >= 1");
    require(options.slots_log2 >= 8 && options.slots_log2 <= 26, "slots_log2 must be in [8, 26]");
    require(options.train_one_in >= 1, "train_one_in must be >= 1");
    require(options.visibility_min_samples >= 0 && options.visibility_min_samples <= kHistoryBits,
            "visibility_min_samples must be in [0, 12]");
    require(options.visibility_recheck_one_in >= 1, "visibility_recheck_one_in must be >= 1");
}

int RadianceCache::cell_level(float cone_width) const {
    const float ratio = options_.cell_footprints * std::max(cone_width, 0.0f) / options_.base_cell_m;
    if (!(ratio > 1.0f)) return 0;
    if (!std::isfinite(ratio)) return kMaxLevel;
    int exponent = 0;
    const float mantissa = std::frexp(ratio, &exponent);           // ratio = mantissa 2^exponent, mantissa in [0.5, 1)
    const int level = mantissa == 0.5f ? exponent - 1 : exponent;  // ceil(log2(ratio)) without log2
    return std::min(kMaxLevel, level);
}

float RadianceCache::level_size(int level) const { return std::ldexp(options_.base_cell_m, level); }

std::uint64_t RadianceCache::key_at_level(const Eigen::Vector3d& world, const Eigen::Vector3f& normal,
                                          int level) const {
    const auto size = static_cast<double>(level_size(level));
    const std::uint64_t octant =
        (normal.x() < 0.0f ? 1u : 0u) | (normal.y() < 0.0f ? 2u : 0u) | (normal.z() < 0.0f ? 4u : 0u);
    std::uint64_t h = mix64((static_cast<std::uint64_t>(level) << 3) | octant);
    for (int axis = 0; axis < 3; ++axis) h = mix64(h ^ cell_coordinate(world[axis], size));
    return h == 0 ? 1 : h;
}

const RadianceCache::Slot* RadianceCache::find(std::uint64_t key) const {
    if (slots_.empty()) return nullptr;
    const std::size_t mask = slots_.size() - 1;
    for (int i = 0; i <= kProbe; ++i) {
        const Slot& s = slots_[(key + static_cast<std::size_t>(i)) & mask];
        if (s.key == key) return &s;
        if (s.key == 0) return nullptr;
    }
    return nullptr;
}

RadianceCache::Slot* RadianceCache::find_or_insert(std::uint64_t key) {
    if (slots_.empty()) slots_.resize(std::size_t{1} << options_.slots_log2);  // on first use only
    const std::size_t mask = slots_.size() - 1;
    for (int i = 0; i <= kProbe; ++i) {
        Slot& s = slots_[(key + static_cast<std::size_t>(i)) & mask];
        if (s.key == key) return &s;
        if (s.key == 0) {
            s.key = key;
            ++cells_;
            return &s;
        }
    }
    return nullptr;
}

bool RadianceCache::lookup(std::uint64_t key, Eigen::Vector3f& white_radiance) const {
    const CellRead cell = read(key);
    if (cell.has_radiance) white_radiance = cell.white;
    return cell.has_radiance;
}

CellVisibility RadianceCache::known_of(const Slot& s) const {
    CellVisibility known;
    const int need = options_.visibility_min_samples;
    if (need == 0) return known;
    const auto window = static_cast<std::uint16_t>((1u << need) - 1u);
    for (int g = 0; g < kVisibilityGroups; ++g) {
        const std::uint16_t state = s.visibility[g];
        if ((state >> kHistoryBits) < need) continue;
        const auto recent = static_cast<std::uint16_t>(state & window);
        if (recent == window) known.visible |= static_cast<std::uint8_t>(1u << g);
        if (recent == 0) known.blocked |= static_cast<std::uint8_t>(1u << g);
    }
    return known;
}

CellVisibility RadianceCache::visibility(std::uint64_t key) const {
    const Slot* s = find(key);
    return s == nullptr ? CellVisibility{} : known_of(*s);
}

CellDirect RadianceCache::direct(std::uint64_t key) const {
    const Slot* s = find(key);
    return s == nullptr ? CellDirect{} : direct_of(*s);
}

CellRead RadianceCache::read(std::uint64_t key) const {
    CellRead out;
    const Slot* s = find(key);
    if (s == nullptr) return out;
    out.has_radiance = s->weight > 0.0f;
    if (out.has_radiance) out.white = Eigen::Vector3f(s->sum[0], s->sum[1], s->sum[2]) / s->weight;
    out.direct = direct_of(*s);
    return out;
}

CellDirect RadianceCache::direct_of(const Slot& s) const {
    CellDirect out;
    const int need = options_.visibility_min_samples;
    out.known = known_of(s);
    bool settled = true;  // every group known or untouched
    for (int g = 0; g < kVisibilityGroups; ++g) {
        const std::uint16_t state = s.visibility[g];
        const int count = state >> kHistoryBits;
        if (count == 0) continue;  // no ray from this cell towards g: its light is in D as traced
        const int recent_count = std::min(count, std::max(need, 1));
        const auto window = static_cast<std::uint16_t>((1u << recent_count) - 1u);
        const auto recent = static_cast<std::uint16_t>(state & window);
        if (recent != 0 && recent != window) out.trainable = false;  // a shadow edge crosses the cell
        if ((out.known.visible | out.known.blocked) & (1u << g)) continue;
        settled = false;
    }
    if (!options_.cache_direct || need == 0 || !settled || !out.trainable) return out;
    if (!(s.direct_weight >= static_cast<float>(need))) return out;
    out.usable = true;
    out.white = Eigen::Vector3f(s.direct_sum[0], s.direct_sum[1], s.direct_sum[2]) / s.direct_weight;
    return out;
}

void RadianceCache::deposit(std::span<const CacheDeposit> deposits) {
    const std::lock_guard lock(pending_mutex_);
    const auto bad = [](const Eigen::Vector3f& v) { return !v.allFinite() || v.minCoeff() < 0.0f; };
    for (CacheDeposit d : deposits) {
        if (d.has_radiance && bad(d.white_radiance)) {
            ++dropped_;
            d.has_radiance = false;  // its other parts still count
        }
        if (d.has_direct && bad(d.direct_white)) {
            ++dropped_;
            d.has_direct = false;
        }
        if (!d.has_radiance && !d.has_direct && d.rays_visible == 0 && d.rays_blocked == 0) continue;
        pending_.push_back(d);
    }
}

void RadianceCache::commit() {
    std::sort(pending_.begin(), pending_.end(), [](const CacheDeposit& a, const CacheDeposit& b) {
        return a.key != b.key ? a.key < b.key : a.order < b.order;
    });
    const auto window = static_cast<float>(options_.max_samples);
    for (const CacheDeposit& d : pending_) {
        Slot* s = find_or_insert(d.key);
        if (s == nullptr) {
            ++dropped_;
            continue;
        }
        for (int g = 0; g < kVisibilityGroups; ++g) {  // a group with both outcomes gets both: mixed
            const auto bit = static_cast<std::uint8_t>(1u << g);
            if ((d.rays_visible & bit) != 0) s->visibility[g] = push_outcome(s->visibility[g], true);
            if ((d.rays_blocked & bit) != 0) s->visibility[g] = push_outcome(s->visibility[g], false);
        }
        if (d.has_radiance) merge(s->sum, s->weight, d.white_radiance, window);
        if (d.has_direct) merge(s->direct_sum, s->direct_weight, d.direct_white, window);
    }
    const std::size_t merged = pending_.size();
    pending_.clear();
    if (pending_.capacity() > 2 * merged) {
        std::vector<CacheDeposit> smaller;
        smaller.reserve(merged);
        pending_.swap(smaller);
    }
}

void RadianceCache::clear() {
    slots_ = {};
    cells_ = 0;
    const std::lock_guard lock(pending_mutex_);
    pending_.clear();
}

}  // namespace mogao
