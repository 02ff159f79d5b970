// SPDX-License-Identifier: Apache-2.0
// The calibration's geometry patterns as a named set, and their files (pattern_catalogue.h).
#include "kiosk/calibrate/pattern_catalogue.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "appliance/autocal/camera_clipping.h"
#include "appliance/autocal/gray_code.h"
#include "appliance/autocal/phase_shift.h"
#include "common/png_io.h"
#include "kiosk/calibrate/pattern_display.h"

namespace mogao::calibrate {
namespace {

namespace fs = std::filesystem;

constexpr std::uint64_t kFnvOffset = 0xcbf29ce484222325ULL;
constexpr std::uint64_t kFnvPrime = 0x100000001b3ULL;

void fnv_byte(std::uint64_t& h, std::uint8_t b) {
    h ^= b;
    h *= kFnvPrime;
}

void fnv_u64(std::uint64_t& h, std::uint64_t v) {
    for (int i = 0; i < 8; ++i) fnv_byte(h, static_cast<std::uint8_t>(v >> (8 * i)));
}

// pattern_display.h's quantisation; the Gray code's 0 and 1 skip the (slow) rounding call.
std::uint8_t code_of(float s) {
    if (!(s > 0.0f)) return 0;  // NaN too, as pattern_display
    if (s >= 1.0f) return 255;
    return static_cast<std::uint8_t>(std::lround(255.0f * s));
}

// One projector's codes: size, channels, then every code row by row.
std::uint64_t projector_hash(const cv::Mat& signal, ImageSize size) {
    std::uint64_t h = kFnvOffset;
    const int channels = signal.empty() ? 1 : signal.channels();
    fnv_u64(h, static_cast<std::uint64_t>(size.width));
    fnv_u64(h, static_cast<std::uint64_t>(size.height));
    fnv_u64(h, static_cast<std::uint64_t>(channels));
    const int n = size.width * channels;
    for (int y = 0; y < size.height; ++y) {
        const float* row = signal.empty() ? nullptr : signal.ptr<float>(y);
        for (int i = 0; i < n; ++i) fnv_byte(h, row == nullptr ? 0 : code_of(row[i]));
    }
    return h;
}

const char* axis_name(bool rows) { return rows ? "rows" : "columns"; }

std::string bit_id(int bit) { return (bit < 10 ? "0" : "") + std::to_string(bit); }

std::string period_text(double period) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", period);
    return buf;
}

std::string kind_name(PatternSpec::Kind k) {
    switch (k) {
        case PatternSpec::Kind::black:
            return "black";
        case PatternSpec::Kind::white:
            return "white";
        case PatternSpec::Kind::projector_white:
            return "projector-white";
        case PatternSpec::Kind::projector_grey:
            return "projector-grey";
        case PatternSpec::Kind::gray_code:
            return "gray-code";
        case PatternSpec::Kind::phase_shift:
            return "phase-shift";
    }
    return "?";
}

// The periods the live run may show, longest last: phase_period_px and 8 x 2^d.
std::vector<double> possible_periods(double nominal, int extent) {
    std::vector<double> out{nominal};
    for (double p = 8.0; p <= 8.0 * extent; p *= 2.0) {
        if (p > nominal) out.push_back(p);
    }
    return out;
}

// The codes of row 0 (columns) or column 0 (rows) of a single-channel signal; empty if the signal
// does not vary along that one axis alone (sampled at its middle line).
std::vector<std::uint8_t> axis_line(const cv::Mat& s, bool rows) {
    if (s.empty() || s.type() != CV_32FC1) return {};
    const cv::Mat1f m = s;
    const int extent = rows ? m.rows : m.cols;
    std::vector<std::uint8_t> line(static_cast<std::size_t>(extent));
    for (int i = 0; i < extent; ++i) {
        const float first = rows ? m(i, 0) : m(0, i);
        const float middle = rows ? m(i, m.cols / 2) : m(m.rows / 2, i);
        if (code_of(first) != code_of(middle)) return {};
        line[static_cast<std::size_t>(i)] = code_of(first);
    }
    return line;
}

}  // namespace

std::string signature_hex(std::uint64_t signature) {
    char buf[24];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(signature));
    return buf;
}

PatternCatalogue::PatternCatalogue(const std::vector<autocal::DeviceModel>& projectors,
                                   const autocal::AutocalOptions& options, std::vector<double> phase_periods_px)
    : options_(options), periods_(std::move(phase_periods_px)) {
    if (options.phase_shifts != 0 && (options.phase_shifts < 3 || options.phase_shifts > 16)) {
        throw std::invalid_argument("phase_shifts: 0 (off) or 3..16, got " + std::to_string(options.phase_shifts));
    }
    if (periods_.empty()) periods_.push_back(options.phase_period_px);
    for (const double p : periods_) {
        if (!(p >= 4.0 && p <= 16384.0)) {
            throw std::invalid_argument("phase period " + period_text(p) + " px outside [4, 16384]");
        }
    }
    for (const autocal::DeviceModel& p : projectors) {
        sizes_.push_back(p.resolution);
        ids_.push_back(p.id);
        black_hash_.push_back(projector_hash(cv::Mat(), p.resolution));
    }
    add("black", {}, "every projector black");
    add("white", {PatternSpec::Kind::white}, "every projector white");
    for (int k = 0; k < static_cast<int>(sizes_.size()); ++k) {
        const std::string p = "p" + std::to_string(k);
        const std::string who = "projector " + std::to_string(k) + " '" + ids_[static_cast<std::size_t>(k)] + "' ";
        add(p + "-white", {PatternSpec::Kind::projector_white, k}, who + "white, the others black");
        add(p + "-grey", {PatternSpec::Kind::projector_grey, k}, who + "grey, the others black");
        for (const bool rows : {false, true}) {
            const ImageSize s = sizes_[static_cast<std::size_t>(k)];
            const int all = autocal::gray_code_bits(rows ? s.height : s.width);
            const int n = options.max_gray_bits > 0 ? std::min(all, options.max_gray_bits) : all;
            for (int bit = 0; bit < n; ++bit) {
                const std::string id = p + "-" + axis_name(rows) + "-bit" + bit_id(bit);
                const std::string what = who + axis_name(rows) + " Gray bit " + std::to_string(bit) + " of " +
                                         std::to_string(all) + " (0 = the coarsest)";
                add(id, {PatternSpec::Kind::gray_code, k, rows, bit, false}, what);
                add(id + "-inverse", {PatternSpec::Kind::gray_code, k, rows, bit, true}, what + ", inverse");
            }
        }
        for (const bool rows : {false, true}) {
            for (const double period : periods_) {
                for (int i = 0; i < options.phase_shifts; ++i) {
                    const PatternSpec spec{PatternSpec::Kind::phase_shift,
                                           k,
                                           rows,
                                           -1,
                                           false,
                                           period,
                                           i,
                                           options.phase_shifts,
                                           options.phase_gamma};
                    add(p + "-" + axis_name(rows) + "-phase-p" + period_text(period) + "-s" + std::to_string(i), spec,
                        who + axis_name(rows) + " phase shift " + std::to_string(i) + " of " +
                            std::to_string(options.phase_shifts) + ", period " + period_text(period) + " px");
                }
            }
        }
    }
}

void PatternCatalogue::add(const std::string& id, const PatternSpec& spec, const std::string& description) {
    const std::uint64_t sig = signature(signals(spec));
    if (by_signature_.contains(sig)) return;  // the same picture as an earlier pattern (one projector: its white)
    by_signature_.emplace(sig, patterns_.size());
    patterns_.push_back({id, static_cast<int>(patterns_.size()), spec, description, sig});
}

std::vector<cv::Mat> PatternCatalogue::signals(const PatternSpec& spec) const {
    std::vector<cv::Mat> out(sizes_.size());
    const auto white = [](ImageSize s) { return cv::Mat1f(s.height, s.width, 1.0f); };
    switch (spec.kind) {
        case PatternSpec::Kind::black:
            break;
        case PatternSpec::Kind::white:
            for (std::size_t k = 0; k < out.size(); ++k) out[k] = white(sizes_[k]);
            break;
        case PatternSpec::Kind::projector_white:
            out.at(static_cast<std::size_t>(spec.projector)) =
                white(sizes_.at(static_cast<std::size_t>(spec.projector)));
            break;
        case PatternSpec::Kind::projector_grey: {
            const ImageSize s = sizes_.at(static_cast<std::size_t>(spec.projector));
            out.at(static_cast<std::size_t>(spec.projector)) = cv::Mat1f(s.height, s.width, autocal::kLitGreySignal);
            break;
        }
        case PatternSpec::Kind::gray_code:
            out.at(static_cast<std::size_t>(spec.projector)) = autocal::gray_code_pattern(
                sizes_.at(static_cast<std::size_t>(spec.projector)), spec.rows, spec.bit, spec.inverse);
            break;
        case PatternSpec::Kind::phase_shift:
            out.at(static_cast<std::size_t>(spec.projector)) =
                autocal::phase_shift_pattern(sizes_.at(static_cast<std::size_t>(spec.projector)), spec.rows,
                                             spec.period_px, spec.shifts, spec.shift, spec.gamma);
            break;
    }
    return out;
}

std::uint64_t PatternCatalogue::signature(const std::vector<cv::Mat>& signals) const {
    if (signals.size() != sizes_.size()) {
        throw std::invalid_argument("pattern: " + std::to_string(signals.size()) + " signals for " +
                                    std::to_string(sizes_.size()) + " projectors");
    }
    std::uint64_t h = kFnvOffset;
    fnv_u64(h, sizes_.size());
    for (std::size_t k = 0; k < signals.size(); ++k) {
        const cv::Mat& s = signals[k];
        if (!s.empty() && (s.cols != sizes_[k].width || s.rows != sizes_[k].height ||
                           (s.type() != CV_32FC1 && s.type() != CV_32FC3))) {
            throw std::invalid_argument("pattern: projector " + std::to_string(k) + "'s signal is not a " +
                                        std::to_string(sizes_[k].width) + "x" + std::to_string(sizes_[k].height) +
                                        " CV_32FC1 or CV_32FC3 image");
        }
        fnv_u64(h, s.empty() ? black_hash_[k] : projector_hash(s, sizes_[k]));
    }
    return h;
}

const CataloguePattern* PatternCatalogue::find(std::uint64_t signature) const {
    const auto it = by_signature_.find(signature);
    return it == by_signature_.end() ? nullptr : &patterns_[it->second];
}

const CataloguePattern* PatternCatalogue::find(const std::string& id) const {
    for (const CataloguePattern& p : patterns_) {
        if (p.id == id) return &p;
    }
    return nullptr;
}

std::string PatternCatalogue::set_signature() const {
    std::uint64_t h = kFnvOffset;
    for (const CataloguePattern& p : patterns_) {
        for (const char c : p.id) fnv_byte(h, static_cast<std::uint8_t>(c));
        fnv_u64(h, p.signature);
    }
    return signature_hex(h);
}

std::optional<std::string> PatternCatalogue::describe_missing_phase(const std::vector<cv::Mat>& signals) const {
    if (options_.phase_shifts == 0 || signals.size() != sizes_.size()) return std::nullopt;
    for (std::size_t k = 0; k < signals.size(); ++k) {
        for (const bool rows : {false, true}) {
            const std::vector<std::uint8_t> line = axis_line(signals[k], rows);
            if (line.empty()) continue;
            const int extent = rows ? sizes_[k].height : sizes_[k].width;
            const ImageSize strip = rows ? ImageSize{1, extent} : ImageSize{extent, 1};
            for (const double period : possible_periods(options_.phase_period_px, extent)) {
                for (int i = 0; i < options_.phase_shifts; ++i) {
                    const cv::Mat1f p = autocal::phase_shift_pattern(strip, rows, period, options_.phase_shifts, i,
                                                                     options_.phase_gamma);
                    bool same = true;
                    for (int j = 0; j < extent && same; ++j) {
                        same = code_of(rows ? p(j, 0) : p(0, j)) == line[static_cast<std::size_t>(j)];
                    }
                    if (!same) continue;
                    return "projector " + std::to_string(k) + " '" + ids_[k] + "' " + axis_name(rows) +
                           " phase shift " + std::to_string(i) + " of " + std::to_string(options_.phase_shifts) +
                           ", period " + period_text(period) + " px";
                }
            }
        }
    }
    return std::nullopt;
}

namespace {

nlohmann::ordered_json spec_json(const PatternSpec& s) {
    nlohmann::ordered_json j = {{"kind", kind_name(s.kind)}};
    if (s.projector >= 0) j["projector"] = s.projector;
    if (s.kind == PatternSpec::Kind::gray_code || s.kind == PatternSpec::Kind::phase_shift)
        j["axis"] = axis_name(s.rows);
    if (s.kind == PatternSpec::Kind::gray_code) {
        j["bit"] = s.bit;
        j["inverse"] = s.inverse;
    }
    if (s.kind == PatternSpec::Kind::phase_shift) {
        j["period_px"] = s.period_px;
        j["shift"] = s.shift;
        j["shifts"] = s.shifts;
        j["gamma"] = s.gamma;
    }
    return j;
}

void write_json(const fs::path& path, const nlohmann::ordered_json& j) {
    const fs::path tmp = path.string() + ".tmp";
    {
        std::ofstream f(tmp);
        f << j.dump(2) << "\n";
        if (!f) throw std::runtime_error("patterns: cannot write '" + tmp.string() + "'");
    }
    fs::rename(tmp, path);
}

}  // namespace

nlohmann::ordered_json write_patterns(const PatternCatalogue& catalogue, const fs::path& out, const std::string& site,
                                      double scale) {
    const std::size_t n = catalogue.sizes().size();
    nlohmann::ordered_json manifest = {{"format", "mogao-calibration-patterns"},
                                       {"version", 1},
                                       {"pattern_set", catalogue.set_signature()},
                                       {"site", site},
                                       {"scale", scale},
                                       {"phase_periods_px", catalogue.phase_periods_px()}};
    for (std::size_t k = 0; k < n; ++k) {
        manifest["projectors"].push_back({{"index", k},
                                          {"id", catalogue.projector_ids()[k]},
                                          {"folder", "p" + std::to_string(k)},
                                          {"width", catalogue.sizes()[k].width},
                                          {"height", catalogue.sizes()[k].height}});
        fs::create_directories(out / ("p" + std::to_string(k)));
    }
    std::vector<std::unordered_map<std::uint64_t, std::string>> written(n);  // per projector: image -> file
    nlohmann::ordered_json captures = nlohmann::ordered_json::object();
    for (const CataloguePattern& p : catalogue.patterns()) {
        const std::vector<cv::Mat> signals = catalogue.signals(p.spec);
        nlohmann::ordered_json entry = {{"id", p.id}, {"order", p.order}, {"description", p.description}};
        entry.update(spec_json(p.spec));
        for (std::size_t k = 0; k < n; ++k) {
            // Black (no signal) is one file per projector, without hashing it again for every pattern.
            const std::uint64_t h = signals[k].empty() ? 0 : projector_hash(signals[k], catalogue.sizes()[k]);
            auto [it, fresh] = written[k].emplace(h, "p" + std::to_string(k) + "/" + p.id + ".png");
            if (fresh) write_png(out / it->second, pattern_content(signals[k], catalogue.sizes()[k]));
            entry["files"][catalogue.projector_ids()[k]] = it->second;
        }
        manifest["patterns"].push_back(entry);
        captures[p.id] = "captures/" + p.id + ".png";
    }
    write_json(out / "patterns.json", manifest);
    write_json(out / "captures.json", {{"format", "mogao-calibration-captures"},
                                       {"version", 1},
                                       {"pattern_set", catalogue.set_signature()},
                                       {"phase_periods_px", catalogue.phase_periods_px()},
                                       {"captures", captures}});
    return manifest;
}

}  // namespace mogao::calibrate
