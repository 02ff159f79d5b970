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
}

float RadianceCache::cell_size(float cone_width) const {
    const float target = options_.cell_footprints * std::max(cone_width, 0.0f);
    int level = 0;
    if (target > options_.base_cell_m) {
        level = std::min(kMaxLevel, static_cast<int>(std::ceil(std::log2(target / options_.base_cell_m))));
    }
    return std::ldexp(options_.base_cell_m, level);
}

std::uint64_t RadianceCache::key(const Eigen::Vector3d& world, const Eigen::Vector3f& normal, float cone_width) const {
    const float size = cell_size(cone_width);
    const auto level = static_cast<std::uint64_t>(std::lround(std::log2(size / options_.base_cell_m)));
    const std::uint64_t octant =
        (normal.x() < 0.0f ? 1u : 0u) | (normal.y() < 0.0f ? 2u : 0u) | (normal.z() < 0.0f ? 4u : 0u);
    std::uint64_t h = mix64((level << 3) | octant);
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
    const Slot* s = find(key);
    if (s == nullptr || !(s->weight > 0.0f)) return false;
    white_radiance = Eigen::Vector3f(s->sum[0], s->sum[1], s->sum[2]) / s->weight;
    return true;
}

void RadianceCache::deposit(std::span<const CacheDeposit> deposits) {
    const std::lock_guard lock(pending_mutex_);
    for (const CacheDeposit& d : deposits) {
        if (!d.white_radiance.allFinite() || d.white_radiance.minCoeff() < 0.0f) {
            ++dropped_;
            continue;
        }
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
        if (s->weight + 1.0f > window) {  // exponential window: older estimates weigh less
            const float keep = (window - 1.0f) / s->weight;
            for (float& c : s->sum) c *= keep;
            s->weight = window - 1.0f;
        }
        for (int c = 0; c < 3; ++c) s->sum[c] += d.white_radiance[c];
        s->weight += 1.0f;
    }
    pending_.clear();
}

void RadianceCache::clear() {
    slots_ = {};
    cells_ = 0;
    const std::lock_guard lock(pending_mutex_);
    pending_.clear();
}

}  // namespace mogao
