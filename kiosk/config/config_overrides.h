// SPDX-License-Identifier: Apache-2.0
// Kiosk configurations made from the one example, kiosk/config/kiosk.example.toml (built into mogao-kiosk):
// tests, image tests and scripts print the example with a few keys overridden
// (`mogao-kiosk --print-config KEY=VALUE... > kiosk.toml`) instead of restating the schema.
//
// An override is "section.key=VALUE"; the section may be dotted ("navigation.control.max_dt_s=0.5")
// and VALUE is a TOML value as it would be written in the file: farm.endpoint="[::1]:7443",
// outputs.sizes=["320x240", "320x240"], display.rate_hz=15. It replaces the key's line in that
// section of the example; a key or a table that the example shows commented out ("# png_dir = ...",
// "# [navigation.control]") is uncommented. An empty VALUE ("stats.file=") comments the key out, so
// that its default applies. Overrides apply in order (a later one wins). A section or key the example
// does not show at all is an error: the example documents every field, and a typo must not pass.
//
// Errors: KioskConfigError naming the override: malformed, unknown section or key, a VALUE spanning
// lines, or a result that is not valid TOML (toml11's message). The result is not otherwise
// validated (its files need not exist yet): load it with load_kiosk_config / --check-config.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "kiosk/config/kiosk_config.h"

namespace mogao {

// kiosk/config/kiosk.example.toml as built (generated from the file by kiosk/CMakeLists.txt).
[[nodiscard]] std::string_view kiosk_example_toml();

// `toml` (the example) with `overrides` applied. Throws KioskConfigError.
[[nodiscard]] std::string apply_config_overrides(std::string_view toml, const std::vector<std::string>& overrides);

// `args` with every "@FILE" replaced by FILE's overrides, one per line; blank lines and lines starting
// with '#' are skipped. Throws KioskConfigError naming an unreadable file.
[[nodiscard]] std::vector<std::string> expand_override_files(const std::vector<std::string>& args);

}  // namespace mogao
