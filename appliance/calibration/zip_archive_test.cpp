// SPDX-License-Identifier: Apache-2.0
#include "appliance/calibration/zip_archive.h"

#include <sys/resource.h>

#include <algorithm>
#include <string>

#include <gtest/gtest.h>

#include "appliance/calibration/mpcdi_error.h"
#include "appliance/calibration/mpcdi_test_util.h"

namespace mogao {
namespace {

std::uint16_t u16(const std::vector<std::uint8_t>& b, std::size_t at) {
    return static_cast<std::uint16_t>(b[at] | b[at + 1] << 8);
}

TEST(ZipArchive, WritesTheReferenceLayoutAndReadsItBack) {
    test::ScratchDir dir;
    const std::vector<std::uint8_t> big(100000, 42);
    write_zip(dir / "a.zip", {{"b.txt", {1, 2, 3}}, {"a.bin", big}, {"empty", {}}}, "test");
    const ZipReader zip(dir / "a.zip", "test");
    const std::vector<std::string> names = {"b.txt", "a.bin", "empty"};
    EXPECT_EQ(zip.names(), names);  // archive order is write order
    EXPECT_EQ(zip.read("a.bin"), big);
    EXPECT_EQ(zip.read("b.txt"), (std::vector<std::uint8_t>{1, 2, 3}));
    EXPECT_TRUE(zip.read("empty").empty());

    // First local header: signature, flags 0, method 8, DOS time 0, date 0x0020, no extra field.
    const std::vector<std::uint8_t> bytes = test::read_bytes(dir / "a.zip");
    ASSERT_GT(bytes.size(), 30U);
    EXPECT_EQ(u16(bytes, 0), 0x4b50);
    EXPECT_EQ(u16(bytes, 6), 0);        // general-purpose flags
    EXPECT_EQ(u16(bytes, 8), 8);        // deflate
    EXPECT_EQ(u16(bytes, 10), 0);       // DOS time
    EXPECT_EQ(u16(bytes, 12), 0x0020);  // DOS date: 1980, month 1, day 0 ("1980-01-00", like the fixtures)
    EXPECT_EQ(u16(bytes, 28), 0);       // no extra field
}

TEST(ZipArchive, EntryNamesMustBeSafe) {
    for (const std::string& bad :
         std::vector<std::string>{"", "/etc/passwd", "../up", "a/../../b", "a\\b", "a//b", "./a", "a\x01"}) {
        EXPECT_THROW(require_safe_entry_name(bad, "t"), MpcdiError) << bad;
    }
    for (const std::string& good : std::vector<std::string>{"mpcdi.xml", "dir/file.pfm", "dir/", "a..b"}) {
        EXPECT_NO_THROW(require_safe_entry_name(good, "t")) << good;
    }
    try {
        require_safe_entry_name("../up", "read_mpcdi 'x.mpcdi'");
    } catch (const MpcdiError& e) {
        EXPECT_STREQ(e.what(), "read_mpcdi 'x.mpcdi': entry '../up': '..' component (path traversal)");
    }
}

TEST(ZipArchive, MissingEntriesAndNonZipFilesAreErrors) {
    test::ScratchDir dir;
    write_zip(dir / "a.zip", {{"x", {1}}}, "test");
    const ZipReader zip(dir / "a.zip", "test");
    EXPECT_THROW((void)zip.read("y"), MpcdiError);
    test::write_bytes(dir / "not.zip", {'h', 'e', 'l', 'l', 'o'});
    EXPECT_THROW(ZipReader(dir / "not.zip", "t"), MpcdiError);
    EXPECT_THROW(ZipReader(dir / "missing.zip", "t"), MpcdiError);
    EXPECT_THROW(write_zip(dir / "no-such-dir" / "a.zip", {{"x", {1}}}, "t"), MpcdiError);
}

long peak_rss_kib() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return usage.ru_maxrss;
}

void put_u32(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) b[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(v >> (8 * i));
}

// A tiny archive whose headers declare a huge entry must be refused without allocating what they
// declare (before the fix, reading it value-initialised a 1 GiB buffer).
TEST(ZipArchive, DeclaredSizeIsNotAllocatedUpFront) {
    test::ScratchDir dir;
    write_zip(dir / "a.zip", {{"x", std::vector<std::uint8_t>(100, 7)}}, "test");
    std::vector<std::uint8_t> bytes = test::read_bytes(dir / "a.zip");
    const std::uint32_t huge = (1U << 30) - 1;  // just under kMaxZipEntryBytes
    put_u32(bytes, 22, huge);                   // local header: uncompressed size
    const std::uint8_t central[] = {0x50, 0x4b, 0x01, 0x02};
    const auto it = std::search(bytes.begin(), bytes.end(), std::begin(central), std::end(central));
    ASSERT_NE(it, bytes.end());
    put_u32(bytes, static_cast<std::size_t>(it - bytes.begin()) + 24, huge);  // central directory
    test::write_bytes(dir / "huge.zip", bytes);
    ASSERT_LT(bytes.size(), 400U);

    const long before = peak_rss_kib();
    const ZipReader zip(dir / "huge.zip", "test");
    try {
        (void)zip.read("x");
        ADD_FAILURE() << "a 100-byte entry declared as 1 GiB was accepted";
    } catch (const MpcdiError& e) {
        EXPECT_NE(std::string(e.what()).find("differs from the 1073741823 bytes its header declares"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_LT(peak_rss_kib() - before, 64 * 1024) << "KiB of peak memory for a 100-byte entry";
}

}  // namespace
}  // namespace mogao
