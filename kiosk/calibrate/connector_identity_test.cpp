// SPDX-License-Identifier: Apache-2.0
// EDID identity, outputs assigned to projectors by what the camera sees, cabling changes.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>

#include "appliance/autocal/autocal.h"
#include "kiosk/calibrate/connector_identity.h"

namespace mogao::calibrate {
namespace {

std::vector<std::uint8_t> edid() {
    std::vector<std::uint8_t> e(128, 0);
    const std::uint8_t header[8] = {0x00, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x00};
    std::memcpy(e.data(), header, 8);
    e[8] = 0x16;  // "EPS": E=5, P=16, S=19 -> 0b0'00101'10000'10011
    e[9] = 0x13;
    e[10] = 0x34;  // product 0x1234
    e[11] = 0x12;
    e[12] = 0x04;  // serial 0x01020304
    e[13] = 0x03;
    e[14] = 0x02;
    e[15] = 0x01;
    e[54 + 3] = 0xFF;
    std::memcpy(&e[54 + 5], "SN12345\n     ", 13);
    e[72 + 3] = 0xFC;
    std::memcpy(&e[72 + 5], "EB-PU1007\n   ", 13);
    e[90] = 0x01;  // a detailed timing descriptor: skipped
    e[90 + 3] = 0xFF;
    return e;
}

TEST(ConnectorIdentity, ParsesEdid) {
    const auto id = parse_edid(edid());
    ASSERT_TRUE(id);
    EXPECT_EQ(id->manufacturer, "EPS");
    EXPECT_EQ(id->product, 0x1234);
    EXPECT_EQ(id->serial, 0x01020304u);
    EXPECT_EQ(id->serial_text, "SN12345");
    EXPECT_EQ(id->name, "EB-PU1007");
    auto bad = edid();
    bad[1] = 0;
    EXPECT_FALSE(parse_edid(bad));
    EXPECT_FALSE(parse_edid(std::span<const std::uint8_t>(edid().data(), 100)));
}

TEST(ConnectorIdentity, ReadsTheConnectorsEdidFromSysfs) {
    const auto dir = std::filesystem::temp_directory_path() / ("mogao-edid-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir / "card1-HDMI-A-2");
    std::filesystem::create_directories(dir / "card1-HDMI-A-1");
    const auto e = edid();
    std::ofstream(dir / "card1-HDMI-A-2" / "edid", std::ios::binary)
        .write(reinterpret_cast<const char*>(e.data()), static_cast<std::streamsize>(e.size()));
    EXPECT_TRUE(read_connector_edid("HDMI-A-2", dir));
    EXPECT_FALSE(read_connector_edid("HDMI-A-1", dir));  // no edid file
    EXPECT_FALSE(read_connector_edid("headless-0", dir));
    std::filesystem::remove_all(dir);
}

TEST(ConnectorIdentity, OutputsAreAssignedLeftToRightByWhatTheCameraSees) {
    cv::Mat1f black(10, 30, 0.0f);
    std::vector<cv::Mat1f> white;
    for (int i = 0; i < 4; ++i) white.push_back(black.clone());
    white[0](cv::Rect(20, 0, 10, 10)) = 1.0f;  // right
    white[1](cv::Rect(0, 0, 10, 10)) = 1.0f;   // left
    white[2](cv::Rect(10, 0, 10, 10)) = 1.0f;  // middle
    white[3](0, 0) = 1.0f;                     // a stray pixel: lights nothing
    const auto lit = lit_outputs(black, white, 0.04);
    ASSERT_EQ(lit.size(), 4u);
    EXPECT_NEAR(lit[1].lit_fraction, 1.0 / 3.0, 1e-12);
    EXPECT_NEAR(lit[0].centroid_x, 25.0, 1e-12);
    const std::vector<std::string> names{"HDMI-A-1", "HDMI-A-2", "DP-1", "DP-2"};
    EXPECT_EQ(assign_projectors(lit, names, {"left", "centre", "right"}, 0.01), (std::vector<std::size_t>{1, 2, 0}));
    try {
        (void)assign_projectors(lit, names, {"a", "b", "c", "d"}, 0.01);
        FAIL() << "a dark output must be refused";
    } catch (const autocal::CalibrationRefused& e) {
        EXPECT_NE(std::string(e.what()).find("projector 3 'd' (connector DP-2)"), std::string::npos) << e.what();
    }
}

TEST(ConnectorIdentity, CablingChangesAreNamed) {
    const nlohmann::json before = {{{"projector", "left"}, {"connector", "HDMI-A-1"}},
                                   {{"projector", "right"}, {"connector", "HDMI-A-2"}}};
    nlohmann::json now = before;
    EXPECT_TRUE(cabling_changes(before, now).empty());
    EXPECT_TRUE(cabling_changes(nullptr, now).empty());
    now[0]["connector"] = "HDMI-A-2";
    now[1]["connector"] = "HDMI-A-1";
    const auto changes = cabling_changes(before, now);
    ASSERT_EQ(changes.size(), 2u);
    EXPECT_NE(changes[0].find("'left' was on connector HDMI-A-1, is now on HDMI-A-2"), std::string::npos) << changes[0];
}

}  // namespace
}  // namespace mogao::calibrate
