// SPDX-License-Identifier: Apache-2.0
// mogao-calibration: make and inspect MPCDI calibration files (docs/calibration.md).
//
//   mogao-calibration ideal --projectors 3 --overlap 0.15 --projector-size 1024x768 --content 1920x1080 --out
//   ideal.mpcdi mogao-calibration info FILE.mpcdi
//
// Exit codes (docs/architecture.md): 0 success, 1 the job failed (unreadable file, write failure,
// failed --check), 2 bad command line.
#pragma once

#include <iosfwd>

namespace mogao {

// The whole program behind main(), testable in-process: `out` gets reports, `err` errors.
[[nodiscard]] int run_calibration_cli(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace mogao
