// SPDX-License-Identifier: Apache-2.0
// tile-costs.json: the per-frame tile times the farm records, input of the load-balance simulator.
//
// Format (docs/load-balancing.md):
//   {"image": {"width": W, "height": H}, "cell_size": 16,
//    "frames": [{"tiles": [[x0, y0, x1, y1, seconds], ...]}, ...]}
// Tiles are half-open pixel rects [x0,x1) x [y0,y1) (common/pixel_rect.h) inside the image,
// normally cell-aligned; seconds is the tile's measured render time (finite, >= 0). Frames are in
// display order. Unknown keys are ignored so the farm may add fields.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "renderfarm/schedule/cost_map.h"

namespace mogao {

struct TileCostLog {
    ImageSize image;
    int cell_size = CostMap::kDefaultCellSize;  // pixels, >= 1
    std::vector<std::vector<TileTime>> frames;  // per frame, its tiles
};

// Parses and validates the JSON text. Throws std::invalid_argument naming the JSON field and the
// limit (e.g. "frames[2].tiles[5][4] (seconds) must be finite and >= 0") on malformed content.
[[nodiscard]] TileCostLog parse_tile_cost_log(std::string_view json_text);
// Reads a file; throws std::runtime_error when it cannot be read, else as parse_tile_cost_log.
[[nodiscard]] TileCostLog read_tile_cost_log(const std::filesystem::path& path);
// Serialises in the format above (what the farm writes).
[[nodiscard]] std::string tile_cost_log_json(const TileCostLog& log);
// One CostMap per frame (CostMap::from_tile_times).
[[nodiscard]] std::vector<CostMap> tile_cost_maps(const TileCostLog& log);

}  // namespace mogao
