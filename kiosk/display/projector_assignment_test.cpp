// SPDX-License-Identifier: Apache-2.0
#include "kiosk/display/projector_assignment.h"

#include <gtest/gtest.h>

namespace mogao {
namespace {

ScreenCalibration screen_of(std::vector<ImageSize> outputs) {
    ScreenCalibration s;
    s.content = {480, 270};
    for (std::size_t i = 0; i < outputs.size(); ++i) {
        ProjectorCalibration p;
        p.id = "proj" + std::to_string(i);
        p.output = outputs[i];
        s.projectors.push_back(p);
    }
    return s;
}

std::vector<OutputInfo> outputs_of(std::vector<ImageSize> sizes) {
    std::vector<OutputInfo> out;
    for (std::size_t i = 0; i < sizes.size(); ++i) out.push_back({"out-" + std::to_string(i), sizes[i], 60.0});
    return out;
}

TEST(AssignProjectors, SameOrderWhenSizesMatch) {
    std::vector<std::string> notes;
    const auto a = assign_projectors(outputs_of({{800, 600}, {800, 600}, {800, 600}}),
                                     screen_of({{800, 600}, {800, 600}, {800, 600}}), &notes);
    ASSERT_EQ(a.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(a[i], i);
    EXPECT_TRUE(notes.empty());
}

TEST(AssignProjectors, MatchesBySizeBeforeOrder) {
    std::vector<std::string> notes;
    const auto a =
        assign_projectors(outputs_of({{1024, 768}, {800, 600}}), screen_of({{800, 600}, {1024, 768}}), &notes);
    EXPECT_EQ(a[0], 1u);
    EXPECT_EQ(a[1], 0u);
    EXPECT_TRUE(notes.empty());
}

TEST(AssignProjectors, OtherSizesAreResampledWithANote) {
    std::vector<std::string> notes;
    const auto a = assign_projectors(outputs_of({{1920, 1080}}), screen_of({{800, 600}}), &notes);
    EXPECT_EQ(a[0], 0u);
    ASSERT_EQ(notes.size(), 1u);
    EXPECT_NE(notes[0].find("resampled"), std::string::npos);
}

TEST(AssignProjectors, ExtraOutputsStayBlackAndExtraProjectorsAreReported) {
    std::vector<std::string> notes;
    auto a = assign_projectors(outputs_of({{800, 600}, {800, 600}}), screen_of({{800, 600}}), &notes);
    EXPECT_EQ(a[0], 0u);
    EXPECT_FALSE(a[1].has_value());
    ASSERT_EQ(notes.size(), 1u);
    EXPECT_NE(notes[0].find("stays black"), std::string::npos);
    notes.clear();
    a = assign_projectors(outputs_of({{800, 600}}), screen_of({{800, 600}, {800, 600}}), &notes);
    ASSERT_EQ(notes.size(), 1u);
    EXPECT_NE(notes[0].find("'proj1' has no output"), std::string::npos);
}

}  // namespace
}  // namespace mogao
