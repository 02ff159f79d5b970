// SPDX-License-Identifier: Apache-2.0
// autocal's PatternSource answered from a folder of captured images (image_folder_source.h).
#include "kiosk/calibrate/image_folder_source.h"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <optional>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "common/codec_errors.h"
#include "common/jpeg_codec.h"
#include "common/png_io.h"

namespace mogao::calibrate {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void bad_field(const fs::path& file, const std::string& field, const std::string& why) {
    throw std::runtime_error(file.string() + ": field '" + field + "' " + why);
}

nlohmann::json parse_json(const fs::path& file) {
    std::ifstream f(file);
    if (!f) {
        throw std::runtime_error(file.string() + ": cannot be read (" + (fs::exists(file) ? "unreadable" : "missing") +
                                 "; `mogao-calibrate patterns` writes one to fill in)");
    }
    try {
        return nlohmann::json::parse(f);
    } catch (const nlohmann::json::exception& e) {
        throw std::runtime_error(file.string() + ": not JSON: " + e.what());
    }
}

std::vector<fs::path> capture_files(const fs::path& file, const fs::path& folder, const std::string& id,
                                    const nlohmann::json& v) {
    const std::string field = "captures." + id;
    std::vector<fs::path> out;
    if (v.is_string()) {
        out.push_back(folder / v.get<std::string>());
    } else if (v.is_array() && !v.empty()) {
        for (const auto& e : v) {
            if (!e.is_string()) bad_field(file, field, "must be a file name or a list of file names");
            out.push_back(folder / e.get<std::string>());
        }
    } else {
        bad_field(file, field, "must be a file name or a non-empty list of file names");
    }
    return out;
}

std::string size_text(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

std::uint32_t big_endian(const unsigned char* p, int bytes) {
    std::uint32_t v = 0;
    for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
    return v;
}

// The size a PNG (IHDR, ISO/IEC 15948 sec. 11.2.2) or JPEG (the first SOFn segment, ITU T.81
// sec. B.2.2) header declares, without decoding; nullopt for other files or a header not found in
// the first 64 KiB (the decoder then has the last word).
std::optional<ImageSize> header_size(const fs::path& file) {
    std::ifstream f(file, std::ios::binary);
    std::vector<unsigned char> b(65536);
    f.read(reinterpret_cast<char*>(b.data()), static_cast<std::streamsize>(b.size()));
    b.resize(static_cast<std::size_t>(f.gcount()));
    static const unsigned char png[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (b.size() >= 24 && std::equal(png, png + 8, b.begin()) && std::equal(b.begin() + 12, b.begin() + 16, "IHDR")) {
        return ImageSize{static_cast<int>(big_endian(&b[16], 4)), static_cast<int>(big_endian(&b[20], 4))};
    }
    if (b.size() < 4 || b[0] != 0xff || b[1] != 0xd8) return std::nullopt;
    for (std::size_t i = 2; i + 9 < b.size();) {
        if (b[i] != 0xff) return std::nullopt;
        const unsigned char m = b[i + 1];
        if (m >= 0xc0 && m <= 0xcf && m != 0xc4 && m != 0xc8 && m != 0xcc) {
            return ImageSize{static_cast<int>(big_endian(&b[i + 7], 2)), static_cast<int>(big_endian(&b[i + 5], 2))};
        }
        i += 2 + big_endian(&b[i + 2], 2);
    }
    return std::nullopt;
}

}  // namespace

CapturesManifest read_captures_manifest(const fs::path& folder) {
    CapturesManifest m;
    m.file = folder / "captures.json";
    const nlohmann::json j = parse_json(m.file);
    if (!j.is_object()) throw std::runtime_error(m.file.string() + ": not a JSON object");
    if (!j.contains("format") || j["format"] != "mogao-calibration-captures")
        bad_field(m.file, "format", "must be \"mogao-calibration-captures\"");
    if (!j.contains("version") || j["version"] != 1) bad_field(m.file, "version", "must be 1");
    if (!j.contains("pattern_set") || !j["pattern_set"].is_string())
        bad_field(m.file, "pattern_set", "is missing (patterns.json's pattern_set, 16 hex digits)");
    m.pattern_set = j["pattern_set"].get<std::string>();
    if (j.contains("phase_periods_px")) {
        const auto& p = j["phase_periods_px"];
        if (!p.is_array() || !std::all_of(p.begin(), p.end(), [](const auto& v) { return v.is_number(); }))
            bad_field(m.file, "phase_periods_px", "must be a list of numbers (projector pixels)");
        for (const auto& v : p) m.phase_periods_px.push_back(v.get<double>());
    }
    if (!j.contains("captures") || !j["captures"].is_object() || j["captures"].empty())
        bad_field(m.file, "captures", "must be an object of pattern id -> file");
    for (const auto& [id, v] : j["captures"].items()) m.captures[id] = capture_files(m.file, folder, id, v);
    return m;
}

void check_captures(const CapturesManifest& m, const PatternCatalogue& catalogue, ImageSize camera) {
    if (m.pattern_set != catalogue.set_signature()) {
        throw std::runtime_error(m.file.string() + ": field 'pattern_set' is " + m.pattern_set +
                                 ", the patterns of this site file, --scale and phase periods are " +
                                 catalogue.set_signature() +
                                 ": the captures are of another pattern set (write the patterns again with the same "
                                 "--site and --scale, and capture them)");
    }
    for (const auto& [id, files] : m.captures) {
        if (catalogue.find(id) == nullptr) {
            throw std::runtime_error(m.file.string() + ": field 'captures." + id +
                                     "': no pattern of that id in the set");
        }
        for (const fs::path& f : files) {
            if (!fs::is_regular_file(f))
                throw std::runtime_error(f.string() + ": missing (the capture of pattern '" + id + "')");
            const std::optional<ImageSize> size = header_size(f);
            if (size && (size->width != camera.width || size->height != camera.height)) {
                throw std::runtime_error(f.string() + ": " + size_text(size->width, size->height) +
                                         ", the site file's camera is " + size_text(camera.width, camera.height) +
                                         " (the capture of pattern '" + id + "')");
            }
        }
    }
    for (const CataloguePattern& p : catalogue.patterns()) {
        if (!m.captures.contains(p.id)) {
            throw std::runtime_error(m.file.string() + ": field 'captures." + p.id + "' is missing: pattern " +
                                     std::to_string(p.order) + " (" + p.description + ") has no capture");
        }
    }
}

Rgb8Image read_capture(const fs::path& file) {
    std::string ext = file.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    try {
        if (ext == ".png") return read_png(file);
        if (ext == ".ppm") return read_ppm(file);
        if (ext == ".jpg" || ext == ".jpeg") {
            std::ifstream f(file, std::ios::binary);
            if (!f) throw DecodeError(file.string() + ": cannot be read");
            const std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
            JpegDecoder decoder;
            return decoder.decode(bytes);
        }
    } catch (const DecodeError& e) {
        const std::string what = e.what();
        throw std::runtime_error(what.find(file.string()) == std::string::npos ? file.string() + ": " + what : what);
    }
    throw std::runtime_error(file.string() + ": not a capture file (.png, .jpg, .jpeg or .ppm)");
}

ImageFolderSource::ImageFolderSource(const PatternCatalogue& catalogue, CapturesManifest m, ImageSize camera_size,
                                     CameraTransfer transfer)
    : catalogue_(&catalogue), manifest_(std::move(m)), camera_size_(camera_size), transfer_(transfer) {}

cv::Mat1f ImageFolderSource::show(const std::vector<cv::Mat>& signals) {
    const CataloguePattern* p = catalogue_->find(catalogue_->signature(signals));
    if (p == nullptr) {
        const auto phase = catalogue_->describe_missing_phase(signals);
        throw std::runtime_error(
            "image " + std::to_string(images_ + 1) + " of the calibration: " +
            (phase ? "it shows " + *phase +
                         ", a phase period the pattern set lacks (the camera resolved fewer Gray bits than the "
                         "projector has, so the period grew): write the patterns again with that period in "
                         "--phase-periods-px, and capture them"
                   : std::string("it shows a pattern that is not in the pattern set (other calibration options?)")));
    }
    const std::vector<fs::path>& files = manifest_.captures.at(p->id);
    std::size_t& next = next_frame_[p->id];
    const fs::path& file = files[next % files.size()];
    ++next;
    const Rgb8Image rgb = read_capture(file);
    if (rgb.size.width != camera_size_.width || rgb.size.height != camera_size_.height) {
        throw std::runtime_error(file.string() + ": " + size_text(rgb.size.width, rgb.size.height) +
                                 ", the site file's camera is " + size_text(camera_size_.width, camera_size_.height) +
                                 " (the capture of pattern '" + p->id + "')");
    }
    CameraFrame frame;
    frame.image = GrayImage(rgb.size.width, rgb.size.height);
    for (std::size_t i = 0; i < frame.image.pixels.size(); ++i) {
        const std::uint8_t* px = &rgb.pixels[3 * i];
        frame.image.pixels[i] = static_cast<std::uint8_t>((px[0] + px[1] + px[2] + 1) / 3);
    }
    frame.colour = rgb;
    cv::Mat1f image = camera_image(frame, transfer_);
    ++images_;
    if (p->spec.kind == PatternSpec::Kind::white) white_ = image.clone();
    return image;
}

void ImageFolderSource::set_relative_exposure(double factor) {
    throw autocal::CalibrationRefused("captured images: the colour step needs the exposure x" + std::to_string(factor) +
                                      ", which a folder of captures cannot follow (calibrate the geometry alone: "
                                      "--no-colour)");
}

}  // namespace mogao::calibrate
