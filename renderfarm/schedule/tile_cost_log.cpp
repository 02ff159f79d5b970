// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/schedule/tile_cost_log.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace mogao {
namespace {

using nlohmann::json;

const json& member(const json& object, const char* key, const std::string& where) {
    if (!object.is_object() || !object.contains(key)) {
        throw std::invalid_argument(fmt::format("tile-costs.json: {} must be an object with key \"{}\"", where, key));
    }
    return object.at(key);
}

int integer(const json& value, const std::string& field, int min) {
    constexpr long long kMax = std::numeric_limits<int>::max();
    // nlohmann stores non-negative literals as unsigned, negative ones as signed.
    const bool ok = value.is_number_unsigned()
                        ? value.get<unsigned long long>() >= static_cast<unsigned long long>(min) &&
                              value.get<unsigned long long>() <= static_cast<unsigned long long>(kMax)
                        : value.is_number_integer() && value.get<long long>() >= min && value.get<long long>() <= kMax;
    if (!ok) {
        throw std::invalid_argument(
            fmt::format("tile-costs.json: {} must be an integer in [{}, {}] (got {})", field, min, kMax, value.dump()));
    }
    return value.get<int>();
}

TileTime parse_tile(const json& value, const std::string& where) {
    if (!value.is_array() || value.size() != 5) {
        throw std::invalid_argument(fmt::format(
            "tile-costs.json: {} must be an array [x0, y0, x1, y1, seconds] (got {})", where, value.dump()));
    }
    TileTime tile;
    tile.rect = {integer(value[0], where + "[0] (x0)", 0), integer(value[1], where + "[1] (y0)", 0),
                 integer(value[2], where + "[2] (x1)", 0), integer(value[3], where + "[3] (y1)", 0)};
    if (!value[4].is_number() || !std::isfinite(value[4].get<double>()) || value[4].get<double>() < 0.0) {
        throw std::invalid_argument(
            fmt::format("tile-costs.json: {}[4] (seconds) must be finite and >= 0 (got {})", where, value[4].dump()));
    }
    tile.seconds = value[4].get<double>();
    return tile;
}

}  // namespace

TileCostLog parse_tile_cost_log(std::string_view json_text) {
    json root;
    try {
        root = json::parse(json_text);
    } catch (const json::parse_error& e) {
        throw std::invalid_argument(fmt::format("tile-costs.json is not valid JSON: {}", e.what()));
    }
    TileCostLog log;
    const json& image = member(root, "image", "the top level");
    log.image.width = integer(member(image, "width", "image"), "image.width", 0);
    log.image.height = integer(member(image, "height", "image"), "image.height", 0);
    log.cell_size = integer(member(root, "cell_size", "the top level"), "cell_size", 1);
    const json& frames = member(root, "frames", "the top level");
    if (!frames.is_array()) {
        throw std::invalid_argument("tile-costs.json: frames must be an array");
    }
    for (std::size_t f = 0; f < frames.size(); ++f) {
        const std::string where = fmt::format("frames[{}]", f);
        const json& tiles = member(frames[f], "tiles", where);
        if (!tiles.is_array()) {
            throw std::invalid_argument(fmt::format("tile-costs.json: {}.tiles must be an array", where));
        }
        auto& out = log.frames.emplace_back();
        for (std::size_t t = 0; t < tiles.size(); ++t) {
            out.push_back(parse_tile(tiles[t], fmt::format("{}.tiles[{}]", where, t)));
        }
    }
    return log;
}

TileCostLog read_tile_cost_log(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    if (!in) {
        throw std::runtime_error(fmt::format("cannot read tile cost log {}", path.string()));
    }
    text << in.rdbuf();  // an empty file inserts nothing and is then reported as invalid JSON
    return parse_tile_cost_log(text.str());
}

std::string tile_cost_log_json(const TileCostLog& log) {
    json frames = json::array();
    for (const auto& tiles : log.frames) {
        json list = json::array();
        for (const TileTime& t : tiles) {
            list.push_back(json::array({t.rect.x0, t.rect.y0, t.rect.x1, t.rect.y1, t.seconds}));
        }
        frames.push_back(json{{"tiles", std::move(list)}});
    }
    const json root{{"image", {{"width", log.image.width}, {"height", log.image.height}}},
                    {"cell_size", log.cell_size},
                    {"frames", std::move(frames)}};
    return root.dump();
}

std::vector<CostMap> tile_cost_maps(const TileCostLog& log) {
    std::vector<CostMap> maps;
    maps.reserve(log.frames.size());
    for (std::size_t f = 0; f < log.frames.size(); ++f) {
        try {
            maps.push_back(CostMap::from_tile_times(log.image, log.cell_size, log.frames[f]));
        } catch (const std::invalid_argument& e) {
            throw std::invalid_argument(fmt::format("tile-costs.json frames[{}]: {}", f, e.what()));
        }
    }
    return maps;
}

}  // namespace mogao
