// SPDX-License-Identifier: Apache-2.0
// The one error type of the MPCDI reader, writer and conversions (docs/architecture.md: file
// readers throw a typed error whose message names the file, the entry or field, and the limit or
// reason; a reader returns a complete value or throws, never a partial one).
#pragma once

#include <stdexcept>

namespace mogao {

struct MpcdiError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

}  // namespace mogao
