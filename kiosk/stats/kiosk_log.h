// SPDX-License-Identifier: Apache-2.0
// Logging of the kiosk (spdlog, stderr): journald-friendly lines "<logger> <level>: <message>",
// no timestamps of our own (the journal adds them). When stderr is the journal (systemd sets
// JOURNAL_STREAM to stderr's device:inode), each line starts with the syslog priority prefix
// "<N>" (sd-daemon(3)) so that journald records warnings and errors at their level.
// The link's logger ("mogao-link", renderfarm/link) is registered here too, so it shares the format.
#pragma once

#include <spdlog/spdlog.h>

namespace mogao {

// Sets the global pattern, makes "mogao-kiosk" the default logger and registers "mogao-link".
// Call once, first thing in main().
void setup_kiosk_logging();

// True when stderr is connected to the journal (JOURNAL_STREAM matches stderr).
[[nodiscard]] bool stderr_is_journal();

}  // namespace mogao
