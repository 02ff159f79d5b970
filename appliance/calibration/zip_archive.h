// SPDX-License-Identifier: Apache-2.0
// The ZIP container of an MPCDI file, through minizip 1.1 (zlib contrib, Debian libminizip-dev):
// the same ZIP layer the reference library used to write the fixtures.
//
// Reading is tolerant of what the reference writer emits (DOS date "1980-01-00" with day 0, version
// made by 0; minizip never validates dates) and strict about what could hurt: names with ".." components, absolute or
// backslash names, duplicate names, encrypted entries, methods other than stored/deflate, entries larger than
// kMaxZipEntryBytes, and CRC mismatches all throw MpcdiError naming the archive and entry. Entries are only ever read
// into memory; nothing is extracted to disk.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace mogao {

// 1 GiB: a 16384x16384 RGB float PFM would be 3 GiB, but real per-pixel warps (4K projectors) are
// about 100 MiB, so this bounds memory against a hostile or corrupt header.
inline constexpr std::uint64_t kMaxZipEntryBytes = std::uint64_t{1} << 30;

class ZipReader {
public:
    // `who` prefixes every error message (e.g. "read_mpcdi '/path/f.mpcdi'").
    ZipReader(const std::filesystem::path& path, std::string who);
    ~ZipReader();
    ZipReader(const ZipReader&) = delete;
    ZipReader& operator=(const ZipReader&) = delete;

    // Entry names in archive order.
    [[nodiscard]] const std::vector<std::string>& names() const { return names_; }
    [[nodiscard]] bool contains(const std::string& name) const;
    // The uncompressed bytes of an entry; throws MpcdiError when missing, too large or corrupt.
    [[nodiscard]] std::vector<std::uint8_t> read(const std::string& name) const;

private:
    void* zip_ = nullptr;  // unzFile
    std::string who_;
    std::vector<std::string> names_;
};

// Throws MpcdiError (prefixed `who`) unless `name` is a safe relative entry name: non-empty, no
// leading '/', no backslash or control character, no empty, "." or ".." component.
void require_safe_entry_name(const std::string& name, const std::string& who);

// Writes a new archive at `path` (replacing any file there) with the entries in order: deflate at
// zlib's default level, no extra fields, no data descriptors, DOS time 0 and date 0x0020
// ("1980-01-00", day 0) and version-made-by 0, as the reference writer does. Throws MpcdiError (prefixed `who`) on
// failure.
void write_zip(const std::filesystem::path& path,
               const std::vector<std::pair<std::string, std::vector<std::uint8_t>>>& entries, const std::string& who);

}  // namespace mogao
