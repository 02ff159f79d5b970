// SPDX-License-Identifier: Apache-2.0
#include "appliance/calibration/mpcdi_types.h"

#include "appliance/calibration/mpcdi_error.h"

#include <cstring>

namespace mogao {

std::string_view to_string(MpcdiProfile value) {
    switch (value) {
        case MpcdiProfile::two_d:
            return "2d";
        case MpcdiProfile::three_d:
            return "3d";
        case MpcdiProfile::advanced_3d:
            return "a3";
        case MpcdiProfile::shader_lamp:
            return "sl";
    }
    return "?";
}

std::string_view to_string(GeometricUnit value) {
    switch (value) {
        case GeometricUnit::mm:
            return "mm";
        case GeometricUnit::cm:
            return "cm";
        case GeometricUnit::dm:
            return "dm";
        case GeometricUnit::m:
            return "m";
        case GeometricUnit::in:
            return "in";
        case GeometricUnit::ft:
            return "ft";
        case GeometricUnit::yd:
            return "yd";
        case GeometricUnit::unknown:
            return "unknown";
    }
    return "?";
}

std::string_view to_string(WarpInterpolation value) {
    switch (value) {
        case WarpInterpolation::linear:
            return "linear";
        case WarpInterpolation::keystone:
            return "keystone";
        case WarpInterpolation::smooth:
            return "smooth";
        case WarpInterpolation::unknown:
            return "unknown";
    }
    return "?";
}

std::string_view to_string(OriginOf3DData value) {
    switch (value) {
        case OriginOf3DData::center_of_mass:
            return "centerOfMass";
        case OriginOf3DData::ideal_eye_point:
            return "idealEyePoint";
        case OriginOf3DData::floor_center:
            return "floorCenter";
        case OriginOf3DData::unknown:
            return "unknown";
    }
    return "?";
}

bool operator==(const PfmMap& a, const PfmMap& b) {
    return a.size == b.size && a.channels == b.channels && a.values.size() == b.values.size() &&
           (a.values.empty() || std::memcmp(a.values.data(), b.values.data(), a.values.size() * sizeof(float)) == 0);
}

std::string response_lut_entry(const std::string& region_id) { return "ResponseLUT-" + region_id + ".pfm"; }

void check_response_lut(const PfmMap& map, const std::string& who) {
    if (map.channels != 3 || map.size.height != 1 || map.size.width < 2 || map.size.width > (1 << 20) ||
        map.values.size() != static_cast<std::size_t>(map.size.width) * 3) {
        throw MpcdiError(who + ": must be a 3-channel PF map of n x 1 samples, n in 2..1048576 (got " +
                         std::to_string(map.channels) + " channel(s), " + std::to_string(map.size.width) + "x" +
                         std::to_string(map.size.height) + ")");
    }
    for (std::size_t i = 0; i < map.values.size(); ++i) {
        const float v = map.values[i];
        const bool rising = i < 3 || v >= map.values[i - 3];
        if (!(v >= 0.0F && v <= 1.0F) || !rising) {
            throw MpcdiError(who + ": sample " + std::to_string(i / 3) + " channel " + std::to_string(i % 3) + " = " +
                             std::to_string(v) + " must be in [0, 1] and not below the previous sample");
        }
    }
}

}  // namespace mogao
