// SPDX-License-Identifier: Apache-2.0
#include "kiosk/config/last_loaded.h"

#include <cstdlib>
#include <span>

#include <spdlog/spdlog.h>

#include "common/file_io.h"

namespace mogao {

std::filesystem::path last_loaded_path(const std::filesystem::path& file) {
    const char* dir = std::getenv("MOGAO_LAST_GOOD_DIR");
    if (dir == nullptr || *dir == '\0') return std::filesystem::path(file.string() + ".last-loaded");
    // One folder for every copy: the file's absolute path, '/' -> '%', names the copy.
    std::string name = std::filesystem::absolute(file).lexically_normal().string();
    for (char& c : name)
        if (c == '/') c = '%';
    return std::filesystem::path(dir) / (name + ".last-loaded");
}

void keep_last_loaded(const std::filesystem::path& file) {
    const std::filesystem::path copy = last_loaded_path(file);
    try {
        const std::vector<std::uint8_t> bytes = read_file_bytes(file, std::uint64_t{1} << 30);
        std::error_code ec;
        std::filesystem::create_directories(copy.parent_path(), ec);  // MOGAO_LAST_GOOD_DIR on first use
        if (std::filesystem::exists(copy, ec) && read_file_bytes(copy, std::uint64_t{1} << 30) == bytes) return;
        write_file_atomically(copy, std::span(bytes.data(), bytes.size()));
    } catch (const std::exception& e) {
        spdlog::warn("last good copy of {}: {}; a bad file at the next start will stop the kiosk", file.string(),
                     e.what());
    }
}

}  // namespace mogao
