// SPDX-License-Identifier: Apache-2.0
// The raw content of an MPCDI file (VESA Multiple Projection Common Data Interchange, v1.0, as
// written by the VESA reference library, github.com/scaredyfish/MPCDI): what read_mpcdi returns and
// write_mpcdi writes, kept faithful to the file so that read -> write -> read is identity.
// Converting to the appliance's ScreenCalibration is mpcdi_screen.h.
//
// Layout: an MPCDI file is a ZIP holding mpcdi.xml and per region a geometry warp (PFM), an alpha
// map (PNG), optionally a beta map (PNG) and a distortion map (PFM), and (mogao's extension) a
// response LUT (PFM, see MpcdiResponseLut). Maps here are converted to the
// project's image convention: row-major, TOP row first (PFM stores rows bottom-to-top; the reader
// flips them), channels interleaved, (0, 0) = top-left.
//
// Units: region x, y, xsize, ysize are normalised to the buffer (0..1, y down); resolutions are
// pixels; frustum angles are degrees; coordinate-frame vectors are in geometricUnit. 2D warps (2d
// and 3d profiles) are normalised coordinates (the examples go slightly outside 0..1); a3 warps are
// 3D points in geometricUnit (metres in the fixtures); sl warps as in the file.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "common/pixel_rect.h"

namespace mogao {

enum class MpcdiProfile { two_d, three_d, advanced_3d, shader_lamp };  // "2d", "3d", "a3", "sl"
enum class GeometricUnit { mm, cm, dm, m, in, ft, yd, unknown };
enum class WarpInterpolation { linear, keystone, smooth, unknown };
enum class OriginOf3DData { center_of_mass, ideal_eye_point, floor_center, unknown };

// The XML spellings: "2d", "m", "linear", "idealEyePoint", "unknown", ...
[[nodiscard]] std::string_view to_string(MpcdiProfile value);
[[nodiscard]] std::string_view to_string(GeometricUnit value);
[[nodiscard]] std::string_view to_string(WarpInterpolation value);
[[nodiscard]] std::string_view to_string(OriginOf3DData value);

// A PFM map (warp or distortion): 3 channels ("PF") or 1 channel ("Pf"), float32.
struct PfmMap {
    ImageSize size;
    int channels = 3;
    std::vector<float> values;  // width * height * channels, top row first
    [[nodiscard]] const float* at(int x, int y) const {
        return values.data() +
               (static_cast<std::size_t>(y) * static_cast<std::size_t>(size.width) + static_cast<std::size_t>(x)) *
                   static_cast<std::size_t>(channels);
    }
    // Bit-wise equality of the values: NaN equals the same NaN, 0 differs from -0 ("identical data").
    friend bool operator==(const PfmMap& a, const PfmMap& b);
};

// A PNG map (alpha or beta): gray (1 channel) or RGB (3 channels), 8 or 16 bits per sample.
struct PngMap {
    ImageSize size;
    int channels = 1;
    int bit_depth = 8;
    std::vector<std::uint16_t> values;  // width * height * channels, top row first, 0..2^bit_depth-1
    [[nodiscard]] std::uint16_t at(int x, int y, int c = 0) const {
        return values[(static_cast<std::size_t>(y) * static_cast<std::size_t>(size.width) +
                       static_cast<std::size_t>(x)) *
                          static_cast<std::size_t>(channels) +
                      static_cast<std::size_t>(c)];
    }
    friend bool operator==(const PngMap&, const PngMap&) = default;
};

struct MpcdiFrustum {  // degrees
    double yaw = 0.0, pitch = 0.0, roll = 0.0;
    double right_angle = 0.0, left_angle = 0.0, up_angle = 0.0, down_angle = 0.0;
    friend bool operator==(const MpcdiFrustum&, const MpcdiFrustum&) = default;
};

struct MpcdiCoordinateFrame {  // position and the yaw/pitch/roll axes, each (x, y, z)
    std::array<double, 3> pos{0, 0, 0}, yaw{0, 0, 1}, pitch{0, 1, 0}, roll{1, 0, 0};
    friend bool operator==(const MpcdiCoordinateFrame&, const MpcdiCoordinateFrame&) = default;
};

struct MpcdiGeometryWarp {
    std::string path;  // ZIP entry name, conventionally "GeometryWarpFile-<regionId>.pfm"
    GeometricUnit geometric_unit = GeometricUnit::unknown;
    WarpInterpolation interpolation = WarpInterpolation::unknown;
    OriginOf3DData origin_of_3d_data = OriginOf3DData::unknown;
    PfmMap map;
    friend bool operator==(const MpcdiGeometryWarp&, const MpcdiGeometryWarp&) = default;
};

struct MpcdiAlphaMap {
    std::string path;             // "AlphaMap-<regionId>.png"
    double gamma_embedded = 2.2;  // linear weight = (value / max)^gamma; 0 = not recorded (SampleMPCDI)
    PngMap map;                   // componentDepth = map.channels, bitDepth = map.bit_depth
    friend bool operator==(const MpcdiAlphaMap&, const MpcdiAlphaMap&) = default;
};

struct MpcdiBetaMap {
    std::string path;  // "BetaMap-<regionId>.png"; may differ in size from the region
    PngMap map;
    friend bool operator==(const MpcdiBetaMap&, const MpcdiBetaMap&) = default;
};

struct MpcdiDistortionMap {
    std::string path;  // "DistortionMapFile-<regionId>.pfm"
    PfmMap map;
    friend bool operator==(const MpcdiDistortionMap&, const MpcdiDistortionMap&) = default;
};

// mogao's extension (not in MPCDI v1.0): the projector's measured inverse response, entry
// "ResponseLUT-<regionId>.pfm" in the same ZIP, found by that name (mpcdi.xml does not reference
// it, so other readers ignore it as an unreferenced entry). A PF map of n x 1 samples (n >= 2):
// sample k holds, per channel r, g, b, the input signal in [0, 1] that gives linear light
// k / (n - 1) of the matched white (ResponseCurve in common/projector_calibration.h).
struct MpcdiResponseLut {
    std::string path;  // always "ResponseLUT-<regionId>.pfm" (the reader finds it by that name)
    PfmMap map;
    friend bool operator==(const MpcdiResponseLut&, const MpcdiResponseLut&) = default;
};

// "ResponseLUT-<regionId>.pfm".
[[nodiscard]] std::string response_lut_entry(const std::string& region_id);
// Throws MpcdiError starting with `who` unless the map is 3 channels, n x 1 with n in
// [2, 1048576], every value finite, in [0, 1] and non-decreasing along the table.
void check_response_lut(const PfmMap& map, const std::string& who);

struct MpcdiRegion {
    std::string id;
    ImageSize resolution;             // Xresolution, Yresolution: the projector's pixels
    double x = 0.0, y = 0.0;          // normalised position in the buffer
    double xsize = 1.0, ysize = 1.0;  // normalised size in the buffer
    std::optional<MpcdiFrustum> frustum;
    std::optional<MpcdiCoordinateFrame> coordinate_frame;
    MpcdiGeometryWarp warp;
    MpcdiAlphaMap alpha;
    std::optional<MpcdiBetaMap> beta;
    std::optional<MpcdiDistortionMap> distortion;
    std::optional<MpcdiResponseLut> response;  // extension, see MpcdiResponseLut
    friend bool operator==(const MpcdiRegion&, const MpcdiRegion&) = default;
};

struct MpcdiBuffer {
    std::string id;
    ImageSize resolution;  // Xresolution, Yresolution
    std::vector<MpcdiRegion> regions;
    friend bool operator==(const MpcdiBuffer&, const MpcdiBuffer&) = default;
};

struct MpcdiFile {
    MpcdiProfile profile = MpcdiProfile::two_d;
    int level = 1;  // 1..4
    std::string version = "1.0";
    std::string date;  // as written, "YYYY-MM-DDThh:mm:ssZ"; empty = write the current UTC time
    std::vector<MpcdiBuffer> buffers;
    friend bool operator==(const MpcdiFile&, const MpcdiFile&) = default;
};

}  // namespace mogao
