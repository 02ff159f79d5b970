// SPDX-License-Identifier: Apache-2.0
// The scanout read-back's pixel conversion (the read-back itself needs a KMS device: it is checked by
// kms_backend_test on real outputs and by the appliance image's QEMU test through mogao-calibrate).
#include "drivers/kms/scanout_reader.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>

namespace mogao {
namespace {

TEST(ScanoutReader, Xrgb8888WordsBecomeRgbBytes) {
    // Two pixels as a little-endian CPU stores 0xXXRRGGBB: bytes B, G, R, X.
    const std::array<std::uint8_t, 8> xrgb{0x30, 0x20, 0x10, 0xff, 0x03, 0x02, 0x01, 0x00};
    std::array<std::uint8_t, 6> rgb{};
    xrgb8888_row_to_rgb8(xrgb.data(), rgb.data(), 2);
    EXPECT_EQ(rgb, (std::array<std::uint8_t, 6>{0x10, 0x20, 0x30, 0x01, 0x02, 0x03}));
}

}  // namespace
}  // namespace mogao
