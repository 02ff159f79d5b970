// SPDX-License-Identifier: Apache-2.0
// Whole-file reads and crash-safe whole-file writes for encoded frames (JPEG, PNG, PPM).
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

namespace mogao {

// Writes `bytes` to a temporary file next to `path`, fsyncs it, then renames it over `path`.
// rename(2) within one directory is atomic, so a reader (the appliance polling a spool folder, a
// viewer) sees either the old file or the complete new one, never a partial frame; the fsync
// keeps a power cut from leaving a renamed-but-empty file. The temporary is removed on failure.
// `exact_mode` (e.g. 0644), when not 0, is set with fchmod before the rename whatever the process
// umask (a file another service's user must read); 0 creates it 0644 under the umask.
// Throws std::system_error whose message names `path` (and the failing step).
void write_file_atomically(const std::filesystem::path& path, std::span<const std::uint8_t> bytes,
                           unsigned exact_mode = 0);

// Reads a whole regular file. Throws std::system_error naming `path` if it cannot be opened or
// read, and std::runtime_error if it is larger than `max_bytes` (a guard against reading a
// multi-gigabyte file by mistake).
[[nodiscard]] std::vector<std::uint8_t> read_file_bytes(const std::filesystem::path& path,
                                                        std::uint64_t max_bytes = std::uint64_t{1} << 31);

}  // namespace mogao
