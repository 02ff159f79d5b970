// SPDX-License-Identifier: Apache-2.0
// Fuzz target: the kiosk'\''s TOML configuration parsed and validated by parse_kiosk_config. Documented errors are
// caught; anything else (a crash, a sanitizer report, an exception of another type) is a finding.
#include <cstddef>
#include <cstdint>

#include "kiosk/config/kiosk_config.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        static_cast<void>(mogao::parse_kiosk_config(mogao::fuzz::text(data, size), "/etc/mogao/kiosk.toml"));
    } catch (const mogao::KioskConfigError&) {}
    return 0;
}
