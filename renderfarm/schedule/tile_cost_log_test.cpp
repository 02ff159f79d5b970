// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/schedule/tile_cost_log.h"

#include <filesystem>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

namespace mogao {
namespace {

constexpr const char* kExample = R"({
  "image": {"width": 40, "height": 20}, "cell_size": 16, "farm": "ignored",
  "frames": [
    {"tiles": [[0, 0, 32, 16, 0.5], [32, 0, 40, 20, 0.25], [0, 16, 32, 20, 0.125]]},
    {"tiles": [[0, 0, 40, 20, 2]]}
  ]})";

std::string message_of(std::string_view text) {
    try {
        (void)parse_tile_cost_log(text);
    } catch (const std::invalid_argument& e) {
        return e.what();
    }
    return "<no std::invalid_argument>";
}

TEST(TileCostLog, ParsesTheDocumentedFormat) {
    const TileCostLog log = parse_tile_cost_log(kExample);
    EXPECT_EQ(log.image, (ImageSize{40, 20}));
    EXPECT_EQ(log.cell_size, 16);
    ASSERT_EQ(log.frames.size(), 2u);
    ASSERT_EQ(log.frames[0].size(), 3u);
    EXPECT_EQ(log.frames[0][1].rect, (PixelRect{32, 0, 40, 20}));
    EXPECT_DOUBLE_EQ(log.frames[0][1].seconds, 0.25);
    EXPECT_DOUBLE_EQ(log.frames[1][0].seconds, 2.0);
}

TEST(TileCostLog, CostMapsConserveEachFramesTime) {
    const auto maps = tile_cost_maps(parse_tile_cost_log(kExample));
    ASSERT_EQ(maps.size(), 2u);
    EXPECT_DOUBLE_EQ(maps[0].total(), 0.875);
    EXPECT_DOUBLE_EQ(maps[1].total(), 2.0);
}

TEST(TileCostLog, RoundTripsThroughJson) {
    const TileCostLog log = parse_tile_cost_log(kExample);
    const TileCostLog again = parse_tile_cost_log(tile_cost_log_json(log));
    EXPECT_EQ(again.image, log.image);
    EXPECT_EQ(again.cell_size, log.cell_size);
    ASSERT_EQ(again.frames.size(), log.frames.size());
    for (std::size_t f = 0; f < log.frames.size(); ++f) {
        ASSERT_EQ(again.frames[f].size(), log.frames[f].size());
        for (std::size_t t = 0; t < log.frames[f].size(); ++t) {
            EXPECT_EQ(again.frames[f][t].rect, log.frames[f][t].rect);
            EXPECT_EQ(again.frames[f][t].seconds, log.frames[f][t].seconds);
        }
    }
}

TEST(TileCostLog, BadContentNamesTheField) {
    EXPECT_NE(message_of("{").find("not valid JSON"), std::string::npos);
    EXPECT_NE(message_of(R"({"cell_size": 16, "frames": []})").find("\"image\""), std::string::npos);
    EXPECT_NE(message_of(R"({"image": {"width": 4, "height": 4}, "cell_size": 0, "frames": []})").find("cell_size"),
              std::string::npos);
    EXPECT_NE(message_of(R"({"image": {"width": -4, "height": 4}, "cell_size": 16, "frames": []})").find("image.width"),
              std::string::npos);
    const std::string neg = message_of(
        R"({"image": {"width": 4, "height": 4}, "cell_size": 16, "frames": [{"tiles": [[0, 0, 4, 4, -1]]}]})");
    EXPECT_NE(neg.find("frames[0].tiles[0][4] (seconds)"), std::string::npos) << neg;
    const std::string arity =
        message_of(R"({"image": {"width": 4, "height": 4}, "cell_size": 16, "frames": [{}, {"tiles": [[0, 0, 4]]}]})");
    EXPECT_NE(arity.find("frames[0]"), std::string::npos) << arity;  // frame 0 lacks "tiles"
    const std::string outside = message_of(
        R"({"image": {"width": 4, "height": 4}, "cell_size": 16, "frames": [{"tiles": [[0, 0, 8, 4, 1]]}]})");
    EXPECT_EQ(outside, "<no std::invalid_argument>");  // parsing is fine; the image check is in tile_cost_maps
    const auto log = parse_tile_cost_log(
        R"({"image": {"width": 4, "height": 4}, "cell_size": 16, "frames": [{"tiles": [[0, 0, 8, 4, 1]]}]})");
    try {
        (void)tile_cost_maps(log);
        FAIL() << "no exception";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("frames[0]"), std::string::npos) << e.what();
    }
}

TEST(TileCostLog, MissingFileIsARuntimeError) {
    EXPECT_THROW((void)read_tile_cost_log(std::filesystem::path(MOGAO_SOURCE_DIR) / "no-such-tile-costs.json"),
                 std::runtime_error);
}

}  // namespace
}  // namespace mogao
