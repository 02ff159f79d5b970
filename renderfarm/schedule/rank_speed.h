// SPDX-License-Identifier: Apache-2.0
// Each render rank's measured speed, so that tile costs describe the image, not the rank.
//
// Tile times are wall-clock. A rank that shares its core with another process (the admin, another
// rank, anything else on a 2-core machine) is descheduled part of the time, and its tiles look
// expensive: fed to the PBT as they are, that region of the next frame is predicted dear and split
// finer, although the pixels cost no more. The rank's speed s_r is the fraction of a core its
// render threads got while it rendered its share: thread CPU time / (wall time x threads), smoothed
// over recent frames with an exponential moving average (s <- a s_frame + (1 - a) s). A tile's
// normalised cost is its wall time x s_r: the time it would have taken on a core of its own.
//
// Units: seconds; speeds in (0, 1]. Errors: bad arguments throw std::invalid_argument.
#pragma once

#include <span>
#include <vector>

#include "renderfarm/schedule/cost_map.h"

namespace mogao {

class RankSpeeds {
public:
    static constexpr double kMinSpeed = 0.05;  // a rank starved below this is still counted at this

    explicit RankSpeeds(double smoothing = 0.5);  // a in (0, 1]

    // Rank `rank` (>= 0) spent `cpu_seconds` of thread CPU time over `wall_seconds` of wall time
    // with `threads` render threads. Frames too short to time (wall <= 0) are ignored.
    void observe(int rank, double cpu_seconds, double wall_seconds, int threads = 1);
    // Smoothed speed of `rank`; 1 before its first observation.
    [[nodiscard]] double speed(int rank) const;

private:
    double smoothing_;
    std::vector<double> speeds_;  // < 0: not observed yet
};

// Tiles of one rank with their seconds multiplied by `speed` (in (0, 1]).
[[nodiscard]] std::vector<TileTime> normalise_tile_times(std::span<const TileTime> tiles, double speed);

}  // namespace mogao
