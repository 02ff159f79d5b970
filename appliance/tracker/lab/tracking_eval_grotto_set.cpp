// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/lab/tracking_eval_grotto.h"

#include <cmath>
#include <cstdio>
#include <fstream>

#include <nlohmann/json.hpp>

namespace mogao::eval {
namespace {

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& field, const std::string& what) {
    throw GrottoSetError(file.string() + ": " + field + ": " + what);
}

double number(const nlohmann::json& j, const char* key, const std::filesystem::path& file, const std::string& where) {
    if (!j.contains(key) || !j[key].is_number() || !std::isfinite(j[key].get<double>()))
        fail(file, where + key, "expected a finite number");
    return j[key].get<double>();
}

GrottoFrame read_frame(const nlohmann::json& f, const std::filesystem::path& folder, const std::filesystem::path& file,
                       const std::string& where) {
    GrottoFrame frame;
    if (!f.contains("variant") || !f["variant"].is_string()) fail(file, where + "variant", "expected a string");
    frame.variant = f["variant"].get<std::string>();
    frame.index = static_cast<int>(number(f, "index", file, where));
    frame.time_s = number(f, "time_s", file, where);
    if (!f.contains("subframes") || !f["subframes"].is_array() || f["subframes"].empty())
        fail(file, where + "subframes", "expected a non-empty array of paths");
    for (const auto& s : f["subframes"]) {
        if (!s.is_string()) fail(file, where + "subframes", "expected paths");
        frame.subframes.push_back(folder / s.get<std::string>());
    }
    if (!f.contains("corners") || !f["corners"].is_array() || f["corners"].size() != 4)
        fail(file, where + "corners", "expected 4 [x, y] pairs");
    for (std::size_t k = 0; k < 4; ++k) {
        const auto& c = f["corners"][k];
        if (!c.is_array() || c.size() != 2 || !c[0].is_number() || !c[1].is_number())
            fail(file, where + "corners", "expected 4 [x, y] pairs");
        frame.corners[k] = {c[0].get<double>(), c[1].get<double>()};
    }
    frame.gain = number(f, "gain", file, where);
    if (!(frame.gain > 0.0 && frame.gain <= 64.0)) fail(file, where + "gain", "must be in (0, 64]");
    frame.noise_seed = static_cast<std::uint64_t>(number(f, "noise_seed", file, where));
    frame.blur_px = number(f, "blur_px", file, where);
    frame.distance_m = number(f, "distance_m", file, where);
    frame.exposure_ms = number(f, "exposure_ms", file, where);
    return frame;
}

}  // namespace

std::filesystem::path GrottoSet::developed(const GrottoFrame& frame) const {
    char name[64];
    std::snprintf(name, sizeof name, "%s-%04d.jpg", frame.variant.c_str(), frame.index);
    return folder / "frames" / name;
}

GrottoSet read_grotto_set(const std::filesystem::path& folder) {
    const auto file = folder / "set.json";
    std::ifstream in(file);
    if (!in) throw GrottoSetError(file.string() + ": cannot open (bench/tracking-grotto/make-grotto-set writes it)");
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {
        throw GrottoSetError(file.string() + ": not valid JSON: " + e.what());
    }
    GrottoSet set;
    set.folder = folder;
    set.camera.width = static_cast<int>(number(j, "width", file, ""));
    set.camera.height = static_cast<int>(number(j, "height", file, ""));
    if (set.camera.width < 16 || set.camera.height < 16 || set.camera.width > 8192 || set.camera.height > 8192)
        fail(file, "width/height", "must be in [16, 8192]");
    if (!j.contains("intrinsics") || !j["intrinsics"].is_object()) fail(file, "intrinsics", "expected an object");
    set.camera.fx = number(j["intrinsics"], "fx", file, "intrinsics.");
    set.camera.fy = number(j["intrinsics"], "fy", file, "intrinsics.");
    set.camera.cx = number(j["intrinsics"], "cx", file, "intrinsics.");
    set.camera.cy = number(j["intrinsics"], "cy", file, "intrinsics.");
    set.tag_size_m = number(j, "tag_size_m", file, "");
    set.tag_id = static_cast<int>(number(j, "tag_id", file, ""));
    set.fps = number(j, "fps", file, "");
    if (!j.contains("family") || !j["family"].is_string()) fail(file, "family", "expected a string");
    set.family = j["family"].get<std::string>();
    if (!j.contains("frames") || !j["frames"].is_array() || j["frames"].empty())
        fail(file, "frames", "expected a non-empty array");
    for (std::size_t i = 0; i < j["frames"].size(); ++i)
        set.frames.push_back(read_frame(j["frames"][i], folder, file, "frames[" + std::to_string(i) + "]."));
    return set;
}

}  // namespace mogao::eval
