// SPDX-License-Identifier: Apache-2.0
#include "appliance/calibration/zip_archive.h"

#include <unzip.h>
#include <zip.h>
#include <zlib.h>

#include <algorithm>
#include <limits>
#include <set>

#include "appliance/calibration/mpcdi_error.h"

namespace mogao {
namespace {

std::string entry_text(const std::string& name) { return "entry '" + name + "'"; }

}  // namespace

void require_safe_entry_name(const std::string& name, const std::string& who) {
    const auto fail = [&](const char* why) { throw MpcdiError(who + ": " + entry_text(name) + ": " + why); };
    if (name.empty()) fail("empty name");
    if (name.front() == '/') fail("absolute path (path traversal)");
    for (const char c : name) {
        if (c == '\\') fail("backslash in the name (path traversal on Windows tools)");
        if (static_cast<unsigned char>(c) < 0x20) fail("control character in the name");
    }
    std::size_t start = 0;
    while (start <= name.size()) {
        const std::size_t end = std::min(name.find('/', start), name.size());
        const std::string_view part(name.data() + start, end - start);
        // A trailing '/' (a directory entry) leaves an empty last part: allowed.
        if (part == "..") fail("'..' component (path traversal)");
        if (part == "." || (part.empty() && end != name.size())) fail("empty or '.' path component");
        start = end + 1;
    }
}

ZipReader::ZipReader(const std::filesystem::path& path, std::string who) : who_(std::move(who)) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) {
        throw MpcdiError(who_ + ": not a regular file or does not exist");
    }
    zip_ = unzOpen64(path.c_str());
    if (zip_ == nullptr) throw MpcdiError(who_ + ": not a ZIP archive (no readable central directory)");
    std::set<std::string> seen;
    try {
        for (int rc = unzGoToFirstFile(zip_); rc != UNZ_END_OF_LIST_OF_FILE; rc = unzGoToNextFile(zip_)) {
            if (rc != UNZ_OK)
                throw MpcdiError(who_ + ": corrupt ZIP central directory (minizip error " + std::to_string(rc) + ")");
            unz_file_info64 info{};
            char name[1024];
            if (unzGetCurrentFileInfo64(zip_, &info, name, sizeof name, nullptr, 0, nullptr, 0) != UNZ_OK ||
                info.size_filename >= sizeof name) {
                throw MpcdiError(who_ + ": unreadable or over-long entry name in the ZIP central directory");
            }
            const std::string entry(name, info.size_filename);
            require_safe_entry_name(entry, who_);
            if (!seen.insert(entry).second)
                throw MpcdiError(who_ + ": " + entry_text(entry) + ": duplicate entry name");
            names_.push_back(entry);
        }
    } catch (...) {
        unzClose(zip_);
        throw;
    }
}

ZipReader::~ZipReader() {
    if (zip_ != nullptr) unzClose(zip_);
}

bool ZipReader::contains(const std::string& name) const {
    return std::find(names_.begin(), names_.end(), name) != names_.end();
}

std::vector<std::uint8_t> ZipReader::read(const std::string& name) const {
    const std::string who = who_ + ": " + entry_text(name);
    if (!contains(name)) throw MpcdiError(who + ": not in the archive");
    // Case-sensitive lookup (iCaseSensitivity 1): MPCDI names come from mpcdi.xml verbatim.
    if (unzLocateFile(zip_, name.c_str(), 1) != UNZ_OK) throw MpcdiError(who + ": cannot be located");
    unz_file_info64 info{};
    if (unzGetCurrentFileInfo64(zip_, &info, nullptr, 0, nullptr, 0, nullptr, 0) != UNZ_OK) {
        throw MpcdiError(who + ": unreadable header");
    }
    if ((info.flag & 1U) != 0) throw MpcdiError(who + ": encrypted entries are not supported");
    if (info.compression_method != 0 && info.compression_method != Z_DEFLATED) {
        throw MpcdiError(who + ": compression method " + std::to_string(info.compression_method) +
                         " is not supported (only 0 stored and 8 deflate)");
    }
    if (info.uncompressed_size > kMaxZipEntryBytes) {
        throw MpcdiError(who + ": " + std::to_string(info.uncompressed_size) + " bytes exceeds the limit of " +
                         std::to_string(kMaxZipEntryBytes));
    }
    if (unzOpenCurrentFile(zip_) != UNZ_OK) throw MpcdiError(who + ": cannot open the entry's data");
    // The buffer grows with the data actually inflated, never to the size the header declares up
    // front: a 100-byte file may declare a 1 GiB entry. One byte past the declared size is asked
    // for, to notice data longer than its header claims.
    const auto declared = static_cast<std::size_t>(info.uncompressed_size);
    constexpr std::size_t kChunk = std::size_t{1} << 20;
    std::vector<std::uint8_t> bytes;
    int rc = 1;
    while (bytes.size() <= declared) {
        const std::size_t old = bytes.size();
        const std::size_t want = std::min(kChunk, declared + 1 - old);
        bytes.resize(old + want);
        rc = unzReadCurrentFile(zip_, bytes.data() + old, static_cast<unsigned>(want));
        bytes.resize(old + static_cast<std::size_t>(std::max(rc, 0)));
        if (rc <= 0) break;
    }
    const int close_rc = unzCloseCurrentFile(zip_);
    if (rc < 0) throw MpcdiError(who + ": corrupt compressed data (minizip error " + std::to_string(rc) + ")");
    if (bytes.size() != declared) {
        throw MpcdiError(who + ": data length differs from the " + std::to_string(declared) +
                         " bytes its header declares");
    }
    if (close_rc == UNZ_CRCERROR) throw MpcdiError(who + ": CRC-32 mismatch (corrupt entry)");
    if (close_rc != UNZ_OK) throw MpcdiError(who + ": minizip error " + std::to_string(close_rc) + " on close");
    return bytes;
}

void write_zip(const std::filesystem::path& path,
               const std::vector<std::pair<std::string, std::vector<std::uint8_t>>>& entries, const std::string& who) {
    zipFile zf = zipOpen64(path.c_str(), APPEND_STATUS_CREATE);
    if (zf == nullptr) throw MpcdiError(who + ": cannot create the ZIP file");
    const auto fail = [&](const std::string& why) {
        zipClose(zf, nullptr);
        throw MpcdiError(who + ": " + why);
    };
    for (const auto& [name, data] : entries) {
        require_safe_entry_name(name, who);
        // A zeroed zip_fileinfo is what the reference writer passed: minizip turns its all-zero
        // tm_zip into DOS time 0x0000 and date 0x0020 (year 1980, month 1, day 0: the fixtures'
        // "1980-01-00"). zip64 = 0 keeps the local headers free of extra fields (entries are
        // bounded far below 4 GiB).
        zip_fileinfo info{};
        if (zipOpenNewFileInZip64(zf, name.c_str(), &info, nullptr, 0, nullptr, 0, nullptr, Z_DEFLATED,
                                  Z_DEFAULT_COMPRESSION, 0) != ZIP_OK) {
            fail(entry_text(name) + ": cannot start the entry");
        }
        std::size_t done = 0;
        while (done < data.size()) {
            const auto chunk = static_cast<unsigned>(std::min<std::size_t>(data.size() - done, 1U << 30));
            if (zipWriteInFileInZip(zf, data.data() + done, chunk) != ZIP_OK) {
                fail(entry_text(name) + ": write failed (disk full?)");
            }
            done += chunk;
        }
        if (zipCloseFileInZip(zf) != ZIP_OK) fail(entry_text(name) + ": cannot finish the entry");
    }
    if (zipClose(zf, nullptr) != ZIP_OK) throw MpcdiError(who + ": cannot finish the ZIP file (disk full?)");
}

}  // namespace mogao
