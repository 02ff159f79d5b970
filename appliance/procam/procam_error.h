// SPDX-License-Identifier: Apache-2.0
// The error of the projector-camera bench calibration's file readers and job (docs/calibration.md,
// "Projector intrinsics on the bench"): the message names the file or folder, the field or image,
// and the limit or reason. Pure maths in this folder throws std::invalid_argument instead.
#pragma once

#include <stdexcept>

namespace mogao::procam {

class ProcamError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

}  // namespace mogao::procam
