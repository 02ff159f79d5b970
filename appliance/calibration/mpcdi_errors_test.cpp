// SPDX-License-Identifier: Apache-2.0
// Bad input gives a clear MpcdiError naming the file, the entry or field, and the reason.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include <gtest/gtest.h>

#include "appliance/calibration/mpcdi_error.h"
#include "appliance/calibration/mpcdi_reader.h"
#include "appliance/calibration/mpcdi_test_util.h"

namespace mogao {
namespace {

class MpcdiErrors : public ::testing::Test {
protected:
    test::ScratchDir dir;
    test::Entries entries = test::small_file_entries();

    // Writes the (possibly corrupted) entries and returns read_mpcdi's error ("" if it read).
    std::string read_error() {
        const std::filesystem::path p = dir / "f.mpcdi";
        write_zip(p, entries, "test");
        return error_at(p);
    }
    static std::string error_at(const std::filesystem::path& p) {
        try {
            (void)read_mpcdi(p);
        } catch (const MpcdiError& e) {
            return e.what();
        }
        return "";
    }
    [[nodiscard]] std::string prefix() const { return "read_mpcdi '" + (dir / "f.mpcdi").string() + "': "; }
    void replace_in_xml(const std::string& from, const std::string& to) {
        std::vector<std::uint8_t>& xml = test::entry(entries, "mpcdi.xml");
        std::string text(xml.begin(), xml.end());
        const std::size_t at = text.find(from);
        ASSERT_NE(at, std::string::npos) << from;
        text.replace(at, from.size(), to);
        xml.assign(text.begin(), text.end());
    }
};

TEST_F(MpcdiErrors, TheUncorruptedFileReads) { EXPECT_EQ(read_error(), ""); }

TEST_F(MpcdiErrors, NotAFileNotAZipNoDescriptor) {
    EXPECT_EQ(error_at(dir / "missing.mpcdi"),
              "read_mpcdi '" + (dir / "missing.mpcdi").string() + "': not a regular file or does not exist");
    test::write_bytes(dir / "f.mpcdi", {'<', 'x', 'm', 'l', '>'});
    EXPECT_EQ(error_at(dir / "f.mpcdi"), prefix() + "not a ZIP archive (no readable central directory)");
    entries.pop_back();  // mpcdi.xml
    EXPECT_EQ(read_error(), prefix() + "no 'mpcdi.xml' entry (not an MPCDI file)");
}

TEST_F(MpcdiErrors, TruncatedOrMismatchedPfm) {
    std::vector<std::uint8_t>& pfm = test::entry(entries, "GeometryWarpFile-p0.pfm");
    pfm.resize(pfm.size() - 5);
    EXPECT_EQ(read_error(), prefix() +
                                "entry 'GeometryWarpFile-p0.pfm': PFM size mismatch: 91 data bytes after the header, "
                                "4x2 x 3 channels x 4 = 96 expected (truncated)");
    pfm = test::small_file_entries()[0].second;
    pfm[3] = '9';  // "PF\n4 2" -> "PF\n9 2": header larger than the data
    EXPECT_NE(read_error().find("4 = 216 expected (truncated)"), std::string::npos);
}

TEST_F(MpcdiErrors, NanIsKeptInfinityIsNamed) {
    std::vector<std::uint8_t>& pfm = test::entry(entries, "GeometryWarpFile-p0.pfm");
    const std::size_t header = std::string("PF\n4 2\n-1.000000\n").size();
    const float nan = NAN;
    std::memcpy(pfm.data() + header, &nan, 4);
    EXPECT_EQ(read_error(), "");
    const float inf = INFINITY;
    std::memcpy(pfm.data() + header, &inf, 4);  // first stored value = bottom-left (0, 1), channel 0
    EXPECT_EQ(read_error(), prefix() +
                                "entry 'GeometryWarpFile-p0.pfm': PFM sample at (0, 1) channel 0 is infinite "
                                "(only finite values or NaN are accepted)");
}

TEST_F(MpcdiErrors, MissingAttributeOrEntry) {
    replace_in_xml(R"( Yresolution="8")", "");
    EXPECT_EQ(read_error(), prefix() + "mpcdi.xml: <region id=\"p0\"> (line 5): missing attribute 'Yresolution'");
    entries = test::small_file_entries();
    replace_in_xml("<path>BetaMap-p0.png</path>", "<path>BetaMap-p9.png</path>");
    EXPECT_EQ(read_error(), prefix() + "entry 'BetaMap-p9.png': not in the archive");
}

TEST_F(MpcdiErrors, PngMustMatchItsDeclaration) {
    replace_in_xml(
        "<componentDepth>1</componentDepth>\n                <bitDepth>8</bitDepth>\n                <gamma",
        "<componentDepth>3</componentDepth>\n                <bitDepth>8</bitDepth>\n                <gamma");
    EXPECT_EQ(read_error(), prefix() +
                                "entry 'AlphaMap-p0.png': PNG has 1 channel(s) of 8 bits but mpcdi.xml declares "
                                "componentDepth 3, bitDepth 8");
}

TEST_F(MpcdiErrors, PathTraversalInZipNamesOrXmlPaths) {
    // Same-length rename in the raw archive ("AA" -> ".."): names are outside the CRC.
    entries.emplace_back("AA/evil.txt", std::vector<std::uint8_t>{1});
    const std::filesystem::path p = dir / "f.mpcdi";
    write_zip(p, entries, "test");
    std::vector<std::uint8_t> bytes = test::read_bytes(p);
    const std::string needle = "AA/evil.txt";
    for (auto it = bytes.begin(); (it = std::search(it, bytes.end(), needle.begin(), needle.end())) != bytes.end();) {
        *it++ = '.';
        *it++ = '.';
    }
    test::write_bytes(p, bytes);
    EXPECT_EQ(error_at(p), prefix() + "entry '../evil.txt': '..' component (path traversal)");

    entries = test::small_file_entries();
    replace_in_xml("<path>BetaMap-p0.png</path>", "<path>/etc/passwd</path>");
    EXPECT_EQ(read_error(), prefix() + "mpcdi.xml path: entry '/etc/passwd': absolute path (path traversal)");
}

TEST_F(MpcdiErrors, CorruptCompressedData) {
    // A big, compressible entry so the deflate stream is long; flip bytes in its middle.
    entries.emplace_back("padding.bin", std::vector<std::uint8_t>(200000, 7));
    const std::filesystem::path p = dir / "f.mpcdi";
    write_zip(p, entries, "test");
    std::vector<std::uint8_t> bytes = test::read_bytes(p);
    // Corrupt the first entry's compressed data (right after its 30-byte header and name).
    const std::size_t data = 30 + std::string("GeometryWarpFile-p0.pfm").size();
    for (std::size_t i = data + 2; i < data + 12; ++i) bytes[i] ^= 0x5A;
    test::write_bytes(p, bytes);
    const std::string e = error_at(p);
    EXPECT_EQ(e.rfind(prefix() + "entry 'GeometryWarpFile-p0.pfm': ", 0), 0U) << e;
    EXPECT_TRUE(e.find("corrupt") != std::string::npos || e.find("CRC") != std::string::npos ||
                e.find("data length") != std::string::npos)
        << e;
}

}  // namespace
}  // namespace mogao
