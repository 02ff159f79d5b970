// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/lab/hand_sequence.h"

#include <unistd.h>

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "appliance/tracker/tag_tracker.h"
#include "drivers/camera/replay_source.h"

namespace mogao {
namespace {

namespace fs = std::filesystem;

TEST(HandSequence, ScriptHasTheDocumentedMoves) {
    const HandSequenceSpec spec;
    EXPECT_NEAR(hand_frame_at(0.5, spec).yaw_deg, 0.0, 1.5);
    EXPECT_NEAR(hand_frame_at(4.0, spec).yaw_deg, 25.0, 1.5);
    EXPECT_NEAR(hand_frame_at(9.8, spec).yaw_deg, -30.0, 1.5);
    EXPECT_NEAR(hand_frame_at(7.5, spec).distance_m, 0.38, 0.01);
    EXPECT_FALSE(hand_frame_at(11.3, spec).visible);
    EXPECT_TRUE(hand_frame_at(11.7, spec).visible);
    HandSequenceSpec half = spec;
    half.seconds = 6.0;  // the script scales
    EXPECT_NEAR(hand_frame_at(2.0, half).yaw_deg, 25.0, 1.5);
    EXPECT_EQ(hand_trajectory(half).size(), 180U);
    half.frames_per_second = 0.0;
    EXPECT_THROW((void)hand_trajectory(half), std::invalid_argument);
}

// The generated folder replays through ReplaySource and tracks back to its truth.
TEST(HandSequence, WrittenFolderReplaysAndTracksToItsTruth) {
    const fs::path dir = fs::temp_directory_path() / ("mogao-hand-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    HandSequenceSpec spec;
    spec.frames_per_second = 1.0;  // the whole 12 s script at real speed, one frame a second
    write_hand_sequence(dir, spec);

    nlohmann::json truth;
    std::ifstream(dir / "truth.json") >> truth;
    ASSERT_EQ(truth["frames"].size(), 12U);
    auto source = ReplaySource::open({dir, 30.0, false});
    ASSERT_TRUE(source.ok()) << source.error().message;
    TrackerConfig config;
    config.camera = read_intrinsics(dir / "camera.json");
    config.tag_size_m = spec.tag_size_m;
    TagTracker tracker(config);
    int hidden = 0;
    for (std::size_t i = 0; i < 12; ++i) {
        auto frame = (*source)->next_frame();
        ASSERT_TRUE(frame.ok()) << frame.error().message;
        const auto& f = truth["frames"][i];
        EXPECT_EQ(frame->timestamp_ns, f["time_ns"].get<std::int64_t>());  // from timestamps.txt
        const TrackedTag t = tracker.track(*frame);
        ASSERT_EQ(t.visible, f["visible"].get<bool>()) << "frame " << i;
        if (!t.visible) {
            ++hidden;
            continue;
        }
        EXPECT_EQ(t.id, 0);
        const Eigen::Vector3d expected(f["translation_m"][0], f["translation_m"][1], f["translation_m"][2]);
        EXPECT_LT((t.pose.translation_m - expected).norm(), 0.005) << "frame " << i;
    }
    EXPECT_EQ(hidden, 1);  // t = 11 s
    fs::remove_all(dir);
}

}  // namespace
}  // namespace mogao
