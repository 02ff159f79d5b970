// SPDX-License-Identifier: Apache-2.0
// Helpers shared by the MPCDI tests: fixture paths, a scratch folder, a small valid file and raw
// ZIP building for corrupt-input tests.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "appliance/calibration/mpcdi_types.h"
#include "appliance/calibration/mpcdi_xml.h"
#include "appliance/calibration/pfm_codec.h"
#include "appliance/calibration/png_codec.h"
#include "appliance/calibration/zip_archive.h"

namespace mogao::test {

inline std::filesystem::path fixture(const std::string& relative) {
    return std::filesystem::path(MOGAO_MPCDI_DIR) / relative;
}

// GTEST_SKIP()s the calling test when the fixture folder is absent (it is never in the repo).
#define MOGAO_REQUIRE_FIXTURES()                                                                      \
    do {                                                                                              \
        if (!std::filesystem::is_directory(std::filesystem::path(MOGAO_MPCDI_DIR) / "custom")) {      \
            GTEST_SKIP() << "MPCDI fixtures not found in " MOGAO_MPCDI_DIR " (../shared/data/mpcdi)"; \
        }                                                                                             \
    } while (0)

inline const std::vector<std::string>& all_fixtures() {
    static const std::vector<std::string> names = {"custom/Media2D_2x1920x1080_L1.mpcdi",
                                                   "custom/Sim3D_1024x768_L4.mpcdi",
                                                   "custom/Advanced3D_3x1024x768_cylinder_L1.mpcdi",
                                                   "examples/Media2D.mpcdi",
                                                   "examples/Sim3D.mpcdi",
                                                   "examples/ShaderLamp.mpcdi",
                                                   "examples/Advanced3D.mpcdi",
                                                   "examples/SampleMPCDI.mpcdi"};
    return names;
}

// A fresh folder per test, removed afterwards.
class ScratchDir {
public:
    ScratchDir() {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        path_ = std::filesystem::temp_directory_path() /
                ("mogao-mpcdi-" + std::to_string(::getpid()) + "-" + info->test_suite_name() + "-" + info->name());
        std::filesystem::remove_all(path_);
        std::filesystem::create_directories(path_);
    }
    ~ScratchDir() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    ScratchDir(const ScratchDir&) = delete;
    ScratchDir& operator=(const ScratchDir&) = delete;
    [[nodiscard]] std::filesystem::path operator/(const std::string& name) const { return path_ / name; }
    [[nodiscard]] const std::filesystem::path& path() const { return path_; }

private:
    std::filesystem::path path_;
};

// A small, valid 2d-profile file: one buffer 64x32, region "p0" 16x8 with a 4x2 warp grid, an 8-bit
// gray alpha ramp and a 2x2 beta map.
inline MpcdiFile small_file() {
    MpcdiFile f;
    f.profile = MpcdiProfile::two_d;
    f.level = 2;
    f.date = "2026-01-02T03:04:05Z";
    MpcdiBuffer b;
    b.id = "buffer1";
    b.resolution = {64, 32};
    MpcdiRegion r;
    r.id = "p0";
    r.resolution = {16, 8};
    r.x = 0.25;
    r.y = 0.0;
    r.xsize = 0.5;
    r.ysize = 1.0;
    r.warp.path = "GeometryWarpFile-p0.pfm";
    r.warp.interpolation = WarpInterpolation::linear;
    r.warp.map.size = {4, 2};
    r.warp.map.channels = 3;
    for (int j = 0; j < 2; ++j) {
        for (int i = 0; i < 4; ++i) {
            r.warp.map.values.push_back(static_cast<float>(i) / 3.0F);
            r.warp.map.values.push_back(static_cast<float>(j));
            r.warp.map.values.push_back(0.0F);
        }
    }
    r.alpha.path = "AlphaMap-p0.png";
    r.alpha.gamma_embedded = 2.2;
    r.alpha.map.size = {16, 8};
    for (int j = 0; j < 8; ++j) {
        for (int i = 0; i < 16; ++i) r.alpha.map.values.push_back(static_cast<std::uint16_t>(i * 17));
    }
    r.beta = MpcdiBetaMap{"BetaMap-p0.png", PngMap{{2, 2}, 1, 8, {0, 1, 2, 3}}};
    b.regions.push_back(r);
    f.buffers.push_back(b);
    return f;
}

using Entries = std::vector<std::pair<std::string, std::vector<std::uint8_t>>>;

// The entries write_mpcdi would write for small_file(), for tests that corrupt one of them.
inline Entries small_file_entries() {
    const MpcdiFile f = small_file();
    const MpcdiRegion& r = f.buffers[0].regions[0];
    const std::string xml = print_mpcdi_xml(f);
    return {{r.warp.path, encode_pfm(r.warp.map, "test")},
            {r.alpha.path, encode_png_map(r.alpha.map, "test")},
            {r.beta->path, encode_png_map(r.beta->map, "test")},
            {"mpcdi.xml", std::vector<std::uint8_t>(xml.begin(), xml.end())}};
}

inline std::vector<std::uint8_t>& entry(Entries& entries, const std::string& name) {
    for (auto& [n, bytes] : entries) {
        if (n == name) return bytes;
    }
    throw std::logic_error("no entry " + name);
}

inline std::vector<std::uint8_t> read_bytes(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void write_bytes(const std::filesystem::path& p, const std::vector<std::uint8_t>& bytes) {
    std::ofstream out(p, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

}  // namespace mogao::test
