// SPDX-License-Identifier: Apache-2.0
// The calibration's geometry patterns as a fixed, named set: what `mogao-calibrate patterns` writes
// (one PNG per pattern per projector, patterns.json) for any camera to capture, and what the
// captured-images route (image_folder_source.h) looks each shown pattern up in.
//
// The set is the live sequence of appliance/autocal's calibrate() (autocal.h, steps 1-2; gray_code.h,
// phase_shift.h) with every step it may take, in the order it takes them (after the camera timing's white, white,
// black, black, camera_timing.h: the same two pictures as `white` and `black`):
//   black                          every projector black
//   white                          every projector white
//   p<k>-white                     projector k white, the others black (shown for the lit edges, each projector
//                                  in turn after `white`, and again before its Gray code: the same picture,
//                                  so a folder of captures holds it once)
//   p<k>-grey                      projector k at grey (autocal::kLitGreySignal), the others black: the lit
//                                  edges' level where the camera clips the white (camera_clipping.h)
//   p<k>-<axis>-bit<BB>            projector k's Gray-code bit BB (0 = the coarsest) along `columns` or
//   p<k>-<axis>-bit<BB>-inverse    `rows`, and its inverse; every bit of the axis (or max_gray_bits):
//                                  the live run stops at the first bit the camera cannot resolve, the
//                                  images route simply leaves the finer captures unused
//   p<k>-<axis>-phase-p<P>-s<I>    phase-shift sinusoid I of `phase_shifts` with a period of P projector
//                                  pixels, pre-compensated for phase_gamma (phase_shift.h)
// Projector k = the site file's k-th projector, left to right. The live run shows a phase period of
// max(phase_period_px, 8 x the finest Gray block it resolved): phase_period_px when the camera resolves
// all but at most two bits, longer otherwise; `phase_periods_px` lists the periods the set holds
// (default: phase_period_px alone).
//
// Identity of a pattern: its signature, FNV-1a (64-bit; Fowler, Noll, Vo) over every projector's
// 8-bit codes round(255 clamp(s, 0, 1)) -- what the projector shows (pattern_display.h) -- with the
// projector count, sizes and channel counts; a projector without a pattern (an empty signal) is black.
// Two signals that give the same codes are the same pattern. The set's signature covers every id and
// pattern signature: a captures manifest written for another site file, scale or option set does
// not match it.
//
// The colour step (colour_calibration.h) is not in the set: it changes the camera's exposure between
// images, which a folder of captures cannot follow.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "appliance/autocal/autocal.h"

namespace mogao::calibrate {

struct PatternSpec {
    enum class Kind { black, white, projector_white, projector_grey, gray_code, phase_shift };
    Kind kind = Kind::black;
    int projector = -1;      // the projector lit (projector_white, projector_grey, gray_code, phase_shift), else -1
    bool rows = false;       // axis: false = columns (stripes vary along x), true = rows
    int bit = -1;            // gray_code: 0 = the coarsest
    bool inverse = false;    // gray_code
    double period_px = 0.0;  // phase_shift: projector pixels
    int shift = -1;          // phase_shift: 0 .. shifts - 1
    int shifts = 0;
    double gamma = 0.0;
};

struct CataloguePattern {
    std::string id;  // as above, unique
    int order = 0;   // position in the live sequence, 0-based
    PatternSpec spec;
    std::string description;  // for people: "projector 0 'proj0' columns Gray bit 3 of 11, inverse"
    std::uint64_t signature = 0;
};

class PatternCatalogue {
public:
    // The set for these projectors (ids and resolutions) and options. `phase_periods_px` empty means
    // {options.phase_period_px}. Throws std::invalid_argument for a period outside [4, 1024] or
    // options autocal would refuse (phase_shifts outside 0 and 3..16).
    PatternCatalogue(const std::vector<autocal::DeviceModel>& projectors, const autocal::AutocalOptions& options,
                     std::vector<double> phase_periods_px = {});

    [[nodiscard]] const std::vector<CataloguePattern>& patterns() const { return patterns_; }
    [[nodiscard]] const std::vector<ImageSize>& sizes() const { return sizes_; }
    [[nodiscard]] const std::vector<std::string>& projector_ids() const { return ids_; }
    [[nodiscard]] const std::vector<double>& phase_periods_px() const { return periods_; }
    // The pattern whose signature this is; nullptr if the set has none.
    [[nodiscard]] const CataloguePattern* find(std::uint64_t signature) const;
    [[nodiscard]] const CataloguePattern* find(const std::string& id) const;
    // Every projector's signal (CV_32FC1, empty = black), as autocal shows it.
    [[nodiscard]] std::vector<cv::Mat> signals(const PatternSpec& spec) const;
    // The signature of `signals` for this set's projectors (above). Throws std::invalid_argument for a
    // count or size other than the set's.
    [[nodiscard]] std::uint64_t signature(const std::vector<cv::Mat>& signals) const;
    // 16 hex digits.
    [[nodiscard]] std::string set_signature() const;
    // For an error message: what `signals` shows if it is a phase-shift pattern of a period the set
    // lacks ("projector 0 'proj0' columns phase shift 3 of 8, period 64 px"), else nullopt.
    [[nodiscard]] std::optional<std::string> describe_missing_phase(const std::vector<cv::Mat>& signals) const;

private:
    void add(const std::string& id, const PatternSpec& spec, const std::string& description);

    std::vector<ImageSize> sizes_;
    std::vector<std::string> ids_;
    autocal::AutocalOptions options_;
    std::vector<double> periods_;
    std::vector<std::uint64_t> black_hash_;  // per projector
    std::vector<CataloguePattern> patterns_;
    std::unordered_map<std::uint64_t, std::size_t> by_signature_;
};

// 16 hex digits of a signature.
[[nodiscard]] std::string signature_hex(std::uint64_t signature);

// `mogao-calibrate patterns`: writes every pattern of `catalogue` into `out` (created): per
// projector a folder `p<k>/` with one 8-bit RGB PNG per pattern at the projector's resolution
// (identical images written once and shared: each projector's black, for instance), `patterns.json`
// (the manifest: format, version, pattern_set, projectors, options, and per pattern its id, order,
// kind, description, parameters and per projector its file) and `captures.json` (the captures
// manifest to fill in: every id -> "captures/<id>.png", image_folder_source.h). `site` and `scale`
// are recorded. Returns patterns.json's content. Throws EncodeError / std::runtime_error naming the file.
nlohmann::ordered_json write_patterns(const PatternCatalogue& catalogue, const std::filesystem::path& out,
                                      const std::string& site, double scale);

}  // namespace mogao::calibrate
