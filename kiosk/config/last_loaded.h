// SPDX-License-Identifier: Apache-2.0
// The kiosk's last good start-up files (docs/kiosk.md, "Bad files at start-up"): every configuration
// and MPCDI calibration that loads and validates at start is copied to `<file>.last-loaded`
// (atomically: temporary, fsync, rename; only when its bytes changed). When the file is bad at the
// next start, the kiosk runs on that copy instead of exiting (a restart loop with dark projectors),
// and says so in the journal, the status file ("fallbacks") and on the wall.
#pragma once

#include <filesystem>
#include <string>

namespace mogao {

// A file the kiosk started on instead of the configured one.
struct StartFallback {
    std::string wall;     // the on-wall line, e.g. "CONFIG ERROR - LAST GOOD IN USE"
    std::string message;  // the journal's and the status file's: the error and the copy used
};

// `<file>.last-loaded`; or, when the environment names MOGAO_LAST_GOOD_DIR (the appliance's unit:
// /var/lib/mogao/last-good, since /etc/mogao is read-only there), that folder's
// `<absolute path with '/' as '%'>.last-loaded`.
[[nodiscard]] std::filesystem::path last_loaded_path(const std::filesystem::path& file);

// Copies `file` to last_loaded_path(file) when the copy is missing or differs. A failure (read-only
// partition, full disk) is logged as a warning and otherwise ignored: the display goes on.
void keep_last_loaded(const std::filesystem::path& file);

}  // namespace mogao
