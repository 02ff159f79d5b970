// SPDX-License-Identifier: Apache-2.0
#include "appliance/calibration/mpcdi_types.h"

#include <cstring>

namespace mogao {

std::string_view to_string(MpcdiProfile value) {
    switch (value) {
        case MpcdiProfile::two_d: return "2d";
        case MpcdiProfile::three_d: return "3d";
        case MpcdiProfile::advanced_3d: return "a3";
        case MpcdiProfile::shader_lamp: return "sl";
    }
    return "?";
}

std::string_view to_string(GeometricUnit value) {
    switch (value) {
        case GeometricUnit::mm: return "mm";
        case GeometricUnit::cm: return "cm";
        case GeometricUnit::dm: return "dm";
        case GeometricUnit::m: return "m";
        case GeometricUnit::in: return "in";
        case GeometricUnit::ft: return "ft";
        case GeometricUnit::yd: return "yd";
        case GeometricUnit::unknown: return "unknown";
    }
    return "?";
}

std::string_view to_string(WarpInterpolation value) {
    switch (value) {
        case WarpInterpolation::linear: return "linear";
        case WarpInterpolation::keystone: return "keystone";
        case WarpInterpolation::smooth: return "smooth";
        case WarpInterpolation::unknown: return "unknown";
    }
    return "?";
}

std::string_view to_string(OriginOf3DData value) {
    switch (value) {
        case OriginOf3DData::center_of_mass: return "centerOfMass";
        case OriginOf3DData::ideal_eye_point: return "idealEyePoint";
        case OriginOf3DData::floor_center: return "floorCenter";
        case OriginOf3DData::unknown: return "unknown";
    }
    return "?";
}

bool operator==(const PfmMap& a, const PfmMap& b) {
    return a.size == b.size && a.channels == b.channels && a.values.size() == b.values.size() &&
           (a.values.empty() || std::memcmp(a.values.data(), b.values.data(), a.values.size() * sizeof(float)) == 0);
}

}  // namespace mogao
