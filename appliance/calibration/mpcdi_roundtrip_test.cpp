// SPDX-License-Identifier: Apache-2.0
// read -> write -> read is identity for every fixture, in the fixtures' own conventions; the ideal
// calibration survives MPCDI.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "appliance/calibration/mpcdi_error.h"
#include "appliance/calibration/mpcdi_reader.h"
#include "appliance/calibration/mpcdi_screen.h"
#include "appliance/calibration/mpcdi_test_util.h"
#include "appliance/calibration/mpcdi_writer.h"
#include "appliance/warp/ideal_calibration.h"
#include "appliance/warp/response_curve.h"

namespace mogao {
namespace {

std::vector<std::string> lines_without_origin(const std::vector<std::uint8_t>& xml) {
    std::vector<std::string> lines;
    std::string line;
    for (const std::uint8_t c : xml) {
        if (c != '\n') {
            line += static_cast<char>(c);
            continue;
        }
        if (line.find("originof3DData") == std::string::npos) lines.push_back(line);
        line.clear();
    }
    return lines;
}

TEST(MpcdiRoundTrip, EveryFixtureReadsBackIdenticalInTheSameLayout) {
    MOGAO_REQUIRE_FIXTURES();
    test::ScratchDir dir;
    for (const std::string& name : test::all_fixtures()) {
        SCOPED_TRACE(name);
        const MpcdiFile original = read_mpcdi(test::fixture(name));
        const std::filesystem::path out = dir / "copy.mpcdi";
        write_mpcdi(out, original);
        const MpcdiFile copy = read_mpcdi(out);
        EXPECT_TRUE(copy == original);

        const ZipReader theirs(test::fixture(name), "fixture");
        const ZipReader ours(out, "copy");
        EXPECT_EQ(ours.names(), theirs.names());  // entry names and order, mpcdi.xml last
        // First local header up to the CRC: version needed, flags, method, DOS time and date.
        const std::vector<std::uint8_t> a = test::read_bytes(out);
        const std::vector<std::uint8_t> b = test::read_bytes(test::fixture(name));
        EXPECT_TRUE(std::equal(a.begin(), a.begin() + 14, b.begin()));
        for (const std::string& entry : theirs.names()) {
            if (entry.ends_with(".pfm")) {
                EXPECT_EQ(ours.read(entry), theirs.read(entry)) << entry;  // byte-identical PFM
            }
        }
        // mpcdi.xml byte-identical except the originof3DData line (real origin instead of the copy
        // of <interpolation>, which differs only where interpolation is not "unknown").
        EXPECT_EQ(lines_without_origin(ours.read("mpcdi.xml")), lines_without_origin(theirs.read("mpcdi.xml")));
        const std::vector<std::uint8_t> xml = ours.read("mpcdi.xml");
        EXPECT_EQ(std::string(xml.begin(), xml.end()).find("<originof3DData>linear"), std::string::npos);
    }
}

TEST(MpcdiRoundTrip, IdealCalibrationSurvivesMpcdi) {
    test::ScratchDir dir;
    const ScreenCalibration ideal = make_ideal_calibration(IdealCalibrationParams{});
    for (const int bits : {8, 16}) {
        SCOPED_TRACE(bits);
        MpcdiExportOptions options;
        options.alpha_bit_depth = bits;
        const MpcdiFile file = to_mpcdi(ideal, options);
        EXPECT_EQ(file.level, 3);  // per-pixel warp, no beta
        write_mpcdi(dir / "ideal.mpcdi", file);
        const ScreenCalibration back = to_screen_calibration(read_mpcdi(dir / "ideal.mpcdi"));
        ASSERT_EQ(back.content, ideal.content);
        ASSERT_EQ(back.projectors.size(), 3U);
        const double blend_bound = alpha_quantisation_bound(bits, 2.2) + 1e-7;
        for (std::size_t k = 0; k < 3; ++k) {
            const ProjectorCalibration& a = ideal.projectors[k];
            const ProjectorCalibration& b = back.projectors[k];
            EXPECT_EQ(b.id, a.id);
            EXPECT_EQ(b.output, a.output);
            ASSERT_EQ(b.warp.size, a.warp.size);
            ASSERT_EQ(b.blend.size, a.blend.size);
            EXPECT_EQ(b.response.lut, a.response.lut);
            double warp_err = 0.0;
            for (std::size_t i = 0; i < a.warp.uv.size(); ++i) {
                warp_err = std::max(warp_err, std::abs(static_cast<double>(a.warp.uv[i]) - b.warp.uv[i]));
            }
            double blend_err = 0.0;
            for (std::size_t i = 0; i < a.blend.weight.size(); ++i) {
                blend_err = std::max(blend_err, std::abs(static_cast<double>(a.blend.weight[i]) - b.blend.weight[i]));
            }
            std::printf("%d-bit alpha, %s: max |warp error| %.3g, max |blend error| %.3g (bound %.3g)\n", bits,
                        a.id.c_str(), warp_err, blend_err, blend_bound);
            EXPECT_LE(warp_err, 1.2e-7);  // float32 rounding of the region-relative warp
            EXPECT_LE(blend_err, blend_bound);
        }
    }
}

TEST(MpcdiRoundTrip, BetaMapsAndMeasuredResponsesSurviveMpcdi) {
    test::ScratchDir dir;
    ScreenCalibration screen = make_ideal_calibration(IdealCalibrationParams{});
    for (std::size_t k = 0; k < screen.projectors.size(); ++k) {
        ProjectorCalibration& p = screen.projectors[k];
        p.beta.size = {p.output.width / 4, p.output.height / 4};
        p.beta.rgb.resize(static_cast<std::size_t>(p.beta.size.pixel_count()) * 3);
        for (std::size_t i = 0; i < p.beta.rgb.size(); ++i) {
            p.beta.rgb[i] = static_cast<float>(0.01 * static_cast<double>((i * 7 + k) % 101) / 100.0);
        }
        p.response = make_gamma_response(2.2, 256);
        p.response.lut[1] = make_gamma_response(1.8 + 0.2 * static_cast<double>(k), 256).lut[1];
    }
    MpcdiExportOptions options;
    options.write_response = true;
    write_mpcdi(dir / "colour.mpcdi", to_mpcdi(screen, options));
    const MpcdiFile file = read_mpcdi(dir / "colour.mpcdi");
    ASSERT_TRUE(file.buffers[0].regions[0].beta.has_value());
    ASSERT_TRUE(file.buffers[0].regions[0].response.has_value());
    EXPECT_EQ(file.buffers[0].regions[0].response->path, "ResponseLUT-proj0.pfm");
    const ScreenCalibration back = to_screen_calibration(file);
    for (std::size_t k = 0; k < screen.projectors.size(); ++k) {
        const ProjectorCalibration& a = screen.projectors[k];
        const ProjectorCalibration& b = back.projectors[k];
        EXPECT_EQ(b.response.lut, a.response.lut);  // float32 PFM: bit-identical
        ASSERT_EQ(b.beta.size, a.beta.size);
        ASSERT_EQ(b.beta.rgb.size(), a.beta.rgb.size());
        double err = 0.0;
        for (std::size_t i = 0; i < a.beta.rgb.size(); ++i) {
            err = std::max(err, std::abs(static_cast<double>(a.beta.rgb[i]) - b.beta.rgb[i]));
        }
        EXPECT_LE(err, 0.5 / 65535.0 + 1e-8);  // half a 16-bit code
    }
    // Second pass: the quantised maps are a fixed point, so the files' maps are identical.
    write_mpcdi(dir / "again.mpcdi", to_mpcdi(back, options));
    const MpcdiFile again = read_mpcdi(dir / "again.mpcdi");
    for (std::size_t k = 0; k < 3; ++k) {
        EXPECT_TRUE(again.buffers[0].regions[k].beta == file.buffers[0].regions[k].beta);
        EXPECT_TRUE(again.buffers[0].regions[k].response == file.buffers[0].regions[k].response);
    }
    // A corrupt LUT (decreasing) is refused by name.
    MpcdiFile bad = file;
    bad.buffers[0].regions[0].response->map.values[3] = 0.9F;
    bad.buffers[0].regions[0].response->map.values[6] = 0.1F;
    EXPECT_THROW(write_mpcdi(dir / "bad.mpcdi", bad), MpcdiError);
}

TEST(MpcdiRoundTrip, WriteIsAtomicAndKeepsTheLastGoodFile) {
    test::ScratchDir dir;
    const std::filesystem::path path = dir / "screen.mpcdi";
    write_mpcdi(path, test::small_file());
    const std::vector<std::uint8_t> good = test::read_bytes(path);
    EXPECT_EQ(std::filesystem::status(path).permissions() & std::filesystem::perms::others_read,
              std::filesystem::perms::others_read);

    MpcdiFile bad = test::small_file();
    bad.buffers[0].regions[0].alpha.map.values.push_back(1);  // inconsistent map: fails while encoding
    EXPECT_THROW(write_mpcdi(path, bad), MpcdiError);
    bad = test::small_file();
    bad.level = 7;
    try {
        write_mpcdi(path, bad);
        FAIL() << "level 7 written";
    } catch (const MpcdiError& e) {
        EXPECT_EQ(std::string(e.what()), "write_mpcdi '" + path.string() + "': level 7 is outside 1..4");
    }
    EXPECT_EQ(test::read_bytes(path), good);
    std::size_t files = 0;
    for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path())) ++files;
    EXPECT_EQ(files, 1U);  // no temporary left behind
    EXPECT_THROW(write_mpcdi(dir / "no-such-dir" / "x.mpcdi", test::small_file()), MpcdiError);
}

TEST(MpcdiRoundTrip, WriterValidatesIdsAndNames) {
    test::ScratchDir dir;
    MpcdiFile f = test::small_file();
    f.buffers[0].regions.push_back(f.buffers[0].regions[0]);
    EXPECT_THROW(write_mpcdi(dir / "x.mpcdi", f), MpcdiError);  // duplicate id
    f = test::small_file();
    f.buffers[0].regions[0].id = "a/b";
    EXPECT_THROW(write_mpcdi(dir / "x.mpcdi", f), MpcdiError);
    f = test::small_file();
    f.buffers[0].regions[0].warp.path = "../x.pfm";
    EXPECT_THROW(write_mpcdi(dir / "x.mpcdi", f), MpcdiError);
    f = test::small_file();
    f.buffers[0].regions[0].warp.path.clear();  // empty: the conventional name
    f.buffers[0].regions[0].alpha.gamma_embedded = NAN;
    EXPECT_THROW(write_mpcdi(dir / "x.mpcdi", f), MpcdiError);
    f.buffers[0].regions[0].alpha.gamma_embedded = 1.0;
    MpcdiFile outside = f;
    outside.buffers[0].regions[0].x = 0.6;  // 0.6 + xsize 0.5 leaves the buffer: the reader would reject it
    EXPECT_THROW(write_mpcdi(dir / "x.mpcdi", outside), MpcdiError);
    outside = f;
    outside.buffers[0].regions[0].frustum = MpcdiFrustum{NAN, 0, 0, 0, 0, 0, 0};
    EXPECT_THROW(write_mpcdi(dir / "x.mpcdi", outside), MpcdiError);
    write_mpcdi(dir / "x.mpcdi", f);
    EXPECT_EQ(read_mpcdi(dir / "x.mpcdi").buffers[0].regions[0].warp.path, "GeometryWarpFile-p0.pfm");
}

}  // namespace
}  // namespace mogao
