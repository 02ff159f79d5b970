// SPDX-License-Identifier: Apache-2.0
#include "appliance/calibration/mpcdi_xml.h"

#include <string>

#include <gtest/gtest.h>

#include "appliance/calibration/mpcdi_error.h"
#include "appliance/calibration/mpcdi_number.h"
#include "appliance/calibration/mpcdi_test_util.h"

namespace mogao {
namespace {

TEST(MpcdiNumber, PrintsPercentGWhenExactElseShortestRoundTrip) {
    EXPECT_EQ(format_number(0.555556), "0.555556");
    EXPECT_EQ(format_number(1.0), "1");
    EXPECT_EQ(format_number(2.2), "2.2");
    EXPECT_EQ(format_number(-30.5), "-30.5");
    EXPECT_EQ(format_number(0.0), "0");
    const double third = 1.0 / 3.0;
    EXPECT_EQ(parse_number(format_number(third)), third);
    EXPECT_EQ(parse_number(" 4.25\n"), 4.25);
    EXPECT_EQ(parse_number("+1"), 1.0);
    EXPECT_FALSE(parse_number("1.5x"));
    EXPECT_FALSE(parse_number("nan"));
    EXPECT_FALSE(parse_number("inf"));
    EXPECT_FALSE(parse_number(""));
    EXPECT_FALSE(parse_int("3.0"));
    EXPECT_EQ(parse_int(" 1024 "), 1024);
}

const char* const kSmallXml = R"(<?xml version="1.0" encoding="UTF-8"?>
<MPCDI profile="2d" date="2026-01-02T03:04:05Z" level="2" version="1.0">
    <display>
        <buffer id="buffer1" Xresolution="64" Yresolution="32">
            <region id="p0" Xresolution="16" Yresolution="8" x="0.25" y="0" xsize="0.5" ysize="1"/>
        </buffer>
    </display>
    <files>
        <fileset region="p0">
            <geometryWarpFile>
                <path>GeometryWarpFile-p0.pfm</path>
                <geometricUnit>unknown</geometricUnit>
                <interpolation>linear</interpolation>
                <originof3DData>unknown</originof3DData>
            </geometryWarpFile>
            <alphaMap>
                <path>AlphaMap-p0.png</path>
                <componentDepth>1</componentDepth>
                <bitDepth>8</bitDepth>
                <gammaEmbedded>2.2</gammaEmbedded>
            </alphaMap>
            <betaMap>
                <path>BetaMap-p0.png</path>
                <bitDepth>8</bitDepth>
                <componentDepth>1</componentDepth>
            </betaMap>
        </fileset>
    </files>
</MPCDI>
)";

TEST(MpcdiXml, PrintsTheReferenceLayout) { EXPECT_EQ(print_mpcdi_xml(test::small_file()), kSmallXml); }

TEST(MpcdiXml, ParsesWhatItPrints) {
    std::vector<std::string> notes;
    const MpcdiFile f = parse_mpcdi_xml(kSmallXml, "t", &notes);
    EXPECT_TRUE(notes.empty());
    MpcdiFile expected = test::small_file();
    for (MpcdiRegion& r : expected.buffers[0].regions) {  // the XML alone carries no map data
        r.warp.map = {};
        r.alpha.map.values.clear();
        r.alpha.map.size = {};
        r.beta->map.values.clear();
        r.beta->map.size = {};
    }
    EXPECT_EQ(f, expected);
}

std::string error_of(const std::string& xml) {
    try {
        (void)parse_mpcdi_xml(xml, "read_mpcdi 'f.mpcdi'", nullptr);
    } catch (const MpcdiError& e) {
        return e.what();
    }
    return "";
}

std::string with(std::string xml, const std::string& from, const std::string& to) {
    const std::size_t at = xml.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return at == std::string::npos ? xml : xml.replace(at, from.size(), to);
}

TEST(MpcdiXml, ErrorsNameTheElementAndField) {
    const std::string base = kSmallXml;
    EXPECT_EQ(error_of(with(base, R"( Xresolution="16")", "")),
              "read_mpcdi 'f.mpcdi': mpcdi.xml: <region id=\"p0\"> (line 5): missing attribute 'Xresolution'");
    EXPECT_NE(
        error_of(with(base, R"(level="2")", R"(level="5")")).find("attribute level=\"5\" is not an integer in [1, 4]"),
        std::string::npos);
    EXPECT_NE(
        error_of(with(base, R"(profile="2d")", R"(profile="4d")")).find("profile=\"4d\" is not one of 2d, 3d, a3, sl"),
        std::string::npos);
    EXPECT_NE(error_of(with(base, R"(version="1.0">)", R"(version="2.0">)")).find("version \"2.0\" is not supported"),
              std::string::npos)
        << error_of(with(base, R"(version="1.0">)", R"(version="2.0">)"));
    EXPECT_NE(error_of(with(base, R"(xsize="0.5")", R"(xsize="0.9")")).find("region extends past the buffer"),
              std::string::npos);
    EXPECT_NE(error_of(with(base, R"(x="0.25")", R"(x="abc")")).find("attribute x=\"abc\" is not a number in [0, 1]"),
              std::string::npos);
    EXPECT_NE(
        error_of(with(base, R"(<fileset region="p0">)", R"(<fileset region="p1">)")).find("no <region> has id \"p1\""),
        std::string::npos);
    EXPECT_NE(
        error_of(with(base, "<gammaEmbedded>2.2<", "<gammaEmbedded>-1<")).find("<gammaEmbedded> -1 is outside [0, 10]"),
        std::string::npos);
    EXPECT_NE(
        error_of(
            with(base,
                 "<componentDepth>1</componentDepth>\n                <bitDepth>8</bitDepth>\n                <gamma",
                 "<componentDepth>2</componentDepth>\n                <bitDepth>8</bitDepth>\n                <gamma"))
            .find("<componentDepth>2</componentDepth> is not one of 1, 3"),
        std::string::npos);
    EXPECT_NE(error_of(with(base, "<path>AlphaMap-p0.png</path>", "")).find("<alphaMap"), std::string::npos);
    EXPECT_NE(error_of(with(base, "<geometricUnit>unknown<", "<geometricUnit>furlong<")).find("is not one of mm, cm"),
              std::string::npos);
    EXPECT_NE(error_of(with(base, "</MPCDI>", "")).find("not well-formed XML"), std::string::npos);
    const std::string fileset =
        base.substr(base.find("        <fileset"), base.find("    </files>") - base.find("        <fileset"));
    EXPECT_NE(
        error_of(with(base, "    </files>", fileset + "    </files>")).find("second <fileset> for the same region"),
        std::string::npos);
    std::string no_files = base.substr(0, base.find("    <files>")) + "</MPCDI>\n";
    EXPECT_NE(error_of(no_files).find("missing child element <files>"), std::string::npos) << error_of(no_files);
}

TEST(MpcdiXml, OriginSpellingsAndTheReferenceWriterBug) {
    const std::string base = kSmallXml;
    std::vector<std::string> notes;
    // The standard's spelling is accepted as well as the reference library's.
    MpcdiFile f = parse_mpcdi_xml(
        with(base, "<originof3DData>unknown</originof3DData>", "<originOf3DData>idealEyePoint</originOf3DData>"), "t",
        &notes);
    EXPECT_EQ(f.buffers[0].regions[0].warp.origin_of_3d_data, OriginOf3DData::ideal_eye_point);
    // The reference writer copies <interpolation> into the origin: read as unknown, with a note.
    f = parse_mpcdi_xml(with(base, "<originof3DData>unknown<", "<originof3DData>linear<"), "t", &notes);
    EXPECT_EQ(f.buffers[0].regions[0].warp.origin_of_3d_data, OriginOf3DData::unknown);
    ASSERT_EQ(notes.size(), 1U);
    EXPECT_NE(notes[0].find("reference writer bug"), std::string::npos);
    // Any other non-origin value is an error.
    EXPECT_NE(
        error_of(with(base, "<originof3DData>unknown<", "<originof3DData>smooth<")).find("is not one of centerOfMass"),
        std::string::npos);
    // The pre-fix reference spelling "unkown" reads as unknown.
    f = parse_mpcdi_xml(with(base, "<geometricUnit>unknown<", "<geometricUnit>unkown<"), "t", nullptr);
    EXPECT_EQ(f.buffers[0].regions[0].warp.geometric_unit, GeometricUnit::unknown);
}

TEST(MpcdiXml, EscapesTextAndPrintsTheRealOrigin) {
    MpcdiFile f = test::small_file();
    f.buffers[0].regions[0].warp.origin_of_3d_data = OriginOf3DData::floor_center;
    f.buffers[0].id = "a&b";
    const std::string xml = print_mpcdi_xml(f);
    EXPECT_NE(xml.find("<originof3DData>floorCenter</originof3DData>"), std::string::npos);
    EXPECT_NE(xml.find(R"(<buffer id="a&amp;b")"), std::string::npos);
    EXPECT_EQ(parse_mpcdi_xml(xml, "t", nullptr).buffers[0].id, "a&b");
    f.date.clear();  // printed as the current UTC time
    EXPECT_NE(print_mpcdi_xml(f).find(R"(Z" level="2")"), std::string::npos);
}

}  // namespace
}  // namespace mogao
