// SPDX-License-Identifier: Apache-2.0
#include "appliance/calibration/pfm_codec.h"

#include <bit>
#include <cmath>
#include <cstring>
#include <string>

#include <gtest/gtest.h>

#include "appliance/calibration/mpcdi_error.h"

namespace mogao {
namespace {

std::vector<std::uint8_t> bytes_of(const std::string& header, const std::vector<float>& values, bool big_endian) {
    std::vector<std::uint8_t> out(header.begin(), header.end());
    for (const float v : values) {
        const auto bits = std::bit_cast<std::uint32_t>(v);
        for (int k = 0; k < 4; ++k) {
            const int shift = big_endian ? 24 - 8 * k : 8 * k;
            out.push_back(static_cast<std::uint8_t>(bits >> shift));
        }
    }
    return out;
}

std::string error_of(const std::vector<std::uint8_t>& bytes) {
    try {
        (void)decode_pfm(bytes, "f.mpcdi: entry 'W.pfm'");
    } catch (const MpcdiError& e) {
        return e.what();
    }
    return "";
}

TEST(PfmCodec, EncodesTheReferenceHeaderAndBottomToTopRows) {
    PfmMap m;
    m.size = {1, 2};
    m.channels = 3;
    m.values = {1, 2, 3, 4, 5, 6};  // top row (1, 2, 3), bottom row (4, 5, 6)
    const std::vector<std::uint8_t> bytes = encode_pfm(m, "test");
    EXPECT_EQ(bytes, bytes_of("PF\n1 2\n-1.000000\n", {4, 5, 6, 1, 2, 3}, false));
    EXPECT_EQ(decode_pfm(bytes, "test"), m);
}

TEST(PfmCodec, ReadsBothByteOrdersAndAnyScaleMagnitude) {
    const std::vector<float> stored = {0.5F, -2.0F, 1e-3F, 7.25F};  // 2x2 gray, bottom row first
    const PfmMap big = decode_pfm(bytes_of("Pf\n2 2\n3.5\n", stored, true), "test");
    const PfmMap little = decode_pfm(bytes_of("Pf 2\t2\r\n-0.25\n", stored, false), "test");
    EXPECT_EQ(big, little);
    EXPECT_EQ(big.channels, 1);
    EXPECT_EQ(*big.at(0, 0), 1e-3F);  // top-left = first value of the last stored row
    EXPECT_EQ(*big.at(1, 1), -2.0F);
}

TEST(PfmCodec, KeepsNanAndRejectsInfinity) {
    const PfmMap m = decode_pfm(bytes_of("Pf\n1 1\n-1\n", {NAN}, false), "test");
    EXPECT_TRUE(std::isnan(m.values[0]));
    const std::string e = error_of(bytes_of("PF\n2 1\n-1\n", {0, 0, 0, 0, INFINITY, 0}, false));
    EXPECT_NE(e.find("entry 'W.pfm': PFM sample at (1, 0) channel 1 is infinite"), std::string::npos) << e;
}

TEST(PfmCodec, HeaderAndSizeErrorsNameTheFieldAndLimit) {
    EXPECT_NE(error_of({'P', '6', '\n'}).find("magic is not 'PF' or 'Pf'"), std::string::npos);
    EXPECT_NE(error_of(bytes_of("PF\n0 4\n-1\n", {}, false)).find("size '0 4' is outside 1..16384"), std::string::npos);
    EXPECT_NE(error_of(bytes_of("PF\n16385 1\n-1\n", {}, false)).find("outside 1..16384"), std::string::npos);
    EXPECT_NE(error_of(bytes_of("PF\n1 1\n0\n", {1, 2, 3}, false)).find("scale '0' is not a non-zero number"),
              std::string::npos);
    EXPECT_NE(error_of(bytes_of("PF\n1 1\nabc\n", {1, 2, 3}, false)).find("scale 'abc'"), std::string::npos);
    EXPECT_NE(error_of(bytes_of("PF\n1 1\n-1", {}, false)).find("not followed by one whitespace"), std::string::npos);
    EXPECT_NE(error_of(bytes_of("PF1 1\n-1\n", {}, false)).find("no whitespace before the width"), std::string::npos);
    const std::string truncated = error_of(bytes_of("PF\n2 2\n-1\n", {1, 2, 3, 4, 5, 6, 7}, false));
    EXPECT_NE(truncated.find("28 data bytes after the header, 2x2 x 3 channels x 4 = 48 expected (truncated)"),
              std::string::npos)
        << truncated;
    const std::string trailing = error_of(bytes_of("Pf\n1 1\n-1\n", {1, 2}, false));
    EXPECT_NE(trailing.find("(trailing bytes)"), std::string::npos) << trailing;
}

TEST(PfmCodec, EncoderRejectsInconsistentMaps) {
    PfmMap m;
    m.size = {2, 2};
    m.channels = 2;
    m.values.assign(8, 0.0F);
    EXPECT_THROW((void)encode_pfm(m, "t"), MpcdiError);
    m.channels = 1;
    m.values.pop_back();
    EXPECT_THROW((void)encode_pfm(m, "t"), MpcdiError);
    m.values.push_back(-INFINITY);
    EXPECT_THROW((void)encode_pfm(m, "t"), MpcdiError);
}

}  // namespace
}  // namespace mogao
