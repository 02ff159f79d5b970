// SPDX-License-Identifier: Apache-2.0
// FrameLog: every presented frame's record appended to a file as one JSON line ([stats].frame_log),
// so that a run of any length keeps every frame on disk while the kiosk's memory stays fixed (the
// statistics file keeps only the first [stats].frames_kept frames). The record is the statistics
// file's per-frame entry (kiosk_stats.h; docs/kiosk.md), without "served_scale" (the reader divides
// "served"'s height by the content's).
//
// The file is truncated when opened (one run per file), written with one write(2) per line (a
// reader never sees half a line unless the disk fills) and opened with O_CLOEXEC. A write that
// fails stops the log (the error is kept and reported in the statistics file): the wall never
// stops for its statistics.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "common/unique_fd.h"

namespace mogao {

class FrameLog {
public:
    // Throws std::system_error naming the path when it cannot be created.
    explicit FrameLog(std::filesystem::path path);

    // Appends `line` and a newline; after a failed write it does nothing.
    void append(const std::string& line);

    [[nodiscard]] const std::filesystem::path& path() const { return path_; }
    [[nodiscard]] std::uint64_t lines() const { return lines_; }
    [[nodiscard]] const std::string& error() const { return error_; }  // empty while it works

private:
    std::filesystem::path path_;
    UniqueFd fd_;
    std::uint64_t lines_ = 0;
    std::string error_;
};

}  // namespace mogao
