#include "drivers/kms/drm_device.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

namespace mogao {
namespace {

TEST(DrmDevice, MissingNodeIsENOENT) {
    auto d = DrmDevice::open("/nonexistent/dri/card0");
    ASSERT_FALSE(d);
    EXPECT_EQ(d.code(), ENOENT);
    EXPECT_NE(d.error().message.find("/nonexistent/dri/card0"), std::string::npos);
}

TEST(DrmDevice, NonKmsNodeIsENODEV) {
    auto d = DrmDevice::open("/dev/null");
    ASSERT_FALSE(d);
    EXPECT_EQ(d.code(), ENODEV);
    EXPECT_NE(d.error().message.find("not a KMS device"), std::string::npos) << d.error().message;
}

TEST(ListDrmCards, SortsCardsByNumberAndIgnoresOtherNodes) {
    const auto dir = std::filesystem::temp_directory_path() / ("mogao-dri-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    for (const char* name : {"card10", "card2", "renderD128", "card0", "cardX", "card"}) std::ofstream(dir / name) << "";
    const auto cards = list_drm_cards(dir);
    ASSERT_EQ(cards.size(), 3u);
    EXPECT_EQ(cards[0].filename(), "card0");
    EXPECT_EQ(cards[1].filename(), "card2");
    EXPECT_EQ(cards[2].filename(), "card10");
    std::filesystem::remove_all(dir);
    EXPECT_TRUE(list_drm_cards(dir).empty());
}

TEST(ConnectorName, UsesKernelTypeNameAndTypeId) {
    drmModeConnector c{};
    c.connector_type = DRM_MODE_CONNECTOR_HDMIA;
    c.connector_type_id = 2;
    EXPECT_EQ(connector_name(c), "HDMI-A-2");
    c.connector_type = DRM_MODE_CONNECTOR_VIRTUAL;
    c.connector_type_id = 1;
    EXPECT_EQ(connector_name(c), "Virtual-1");
}

}  // namespace
}  // namespace mogao
