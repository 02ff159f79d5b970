// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/schedule/rank_speed.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mogao {

RankSpeeds::RankSpeeds(double smoothing) : smoothing_(smoothing) {
    if (!(smoothing > 0 && smoothing <= 1)) throw std::invalid_argument("RankSpeeds: smoothing must be in (0, 1]");
}

void RankSpeeds::observe(int rank, double cpu_seconds, double wall_seconds, int threads) {
    if (rank < 0) throw std::invalid_argument("RankSpeeds: rank must be >= 0");
    if (threads < 1) throw std::invalid_argument("RankSpeeds: threads must be >= 1");
    if (!(wall_seconds > 0) || !std::isfinite(wall_seconds) || !std::isfinite(cpu_seconds)) return;
    const double now = std::clamp(cpu_seconds / (wall_seconds * threads), kMinSpeed, 1.0);
    if (speeds_.size() <= static_cast<std::size_t>(rank)) speeds_.resize(static_cast<std::size_t>(rank) + 1, -1.0);
    double& s = speeds_[static_cast<std::size_t>(rank)];
    s = s < 0 ? now : smoothing_ * now + (1 - smoothing_) * s;
}

double RankSpeeds::speed(int rank) const {
    if (rank < 0 || static_cast<std::size_t>(rank) >= speeds_.size()) return 1.0;
    const double s = speeds_[static_cast<std::size_t>(rank)];
    return s < 0 ? 1.0 : s;
}

std::vector<TileTime> normalise_tile_times(std::span<const TileTime> tiles, double speed) {
    if (!(speed > 0 && speed <= 1)) throw std::invalid_argument("normalise_tile_times: speed must be in (0, 1]");
    std::vector<TileTime> out(tiles.begin(), tiles.end());
    for (TileTime& t : out) t.seconds *= speed;
    return out;
}

}  // namespace mogao
