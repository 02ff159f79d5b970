// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/lab/tags_real.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <stdexcept>

#include <nlohmann/json.hpp>

namespace mogao {
namespace {

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what) {
    throw std::runtime_error(path.string() + ": " + what);
}

RealImageTruth parse_image(const std::filesystem::path& path, const nlohmann::json& j, std::size_t index) {
    const std::string where = "images[" + std::to_string(index) + "]";
    RealImageTruth t;
    try {
        t.file = j.at("file").get<std::string>();
        t.family = j.value("family", t.family);
        t.tags = j.at("tags").get<int>();
        t.count_source = j.value("count_source", "");
        t.ids = j.value("ids", std::vector<int>{});
        t.ids_source = j.value("ids_source", "");
        t.subset = j.value("subset", t.subset);
        for (const auto& r : j.value("reference", nlohmann::json::array())) {
            RealReference ref;
            ref.id = r.at("id").get<int>();
            const auto corners = r.at("corners").get<std::vector<std::array<double, 2>>>();
            if (corners.size() != 4)
                fail(path, where + ".reference: id " + std::to_string(ref.id) + " needs 4 corners");
            for (std::size_t i = 0; i < 4; ++i) ref.corners[i] = {corners[i][0], corners[i][1]};
            t.reference.push_back(ref);
        }
    } catch (const nlohmann::json::exception& e) {
        fail(path, where + ": " + e.what());
    }
    if (t.tags < 1) fail(path, where + ".tags = " + std::to_string(t.tags) + " must be >= 1");
    return t;
}

}  // namespace

std::vector<RealImageTruth> read_real_truth(const std::filesystem::path& path) {
    std::ifstream in(path);
    if (!in) fail(path, "cannot be read");
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {
        fail(path, std::string("not JSON: ") + e.what());
    }
    if (!j.contains("images") || !j["images"].is_array()) fail(path, "no \"images\" array");
    std::vector<RealImageTruth> out;
    for (std::size_t i = 0; i < j["images"].size(); ++i) out.push_back(parse_image(path, j["images"][i], i));
    return out;
}

void write_real_truth(const std::filesystem::path& path, const std::vector<RealImageTruth>& images) {
    std::ofstream out(path);
    if (!out) fail(path, "cannot be written");
    out << "{\"images\": [\n";
    for (std::size_t i = 0; i < images.size(); ++i) {
        const auto& t = images[i];
        nlohmann::json j{
            {"file", t.file}, {"family", t.family},         {"tags", t.tags},    {"count_source", t.count_source},
            {"ids", t.ids},   {"ids_source", t.ids_source}, {"subset", t.subset}};
        j["reference"] = nlohmann::json::array();
        for (const auto& r : t.reference) {
            nlohmann::json corners = nlohmann::json::array();
            for (const auto& c : r.corners)
                corners.push_back({std::round(c.x() * 1000) / 1000, std::round(c.y() * 1000) / 1000});
            j["reference"].push_back({{"id", r.id}, {"corners", corners}});
        }
        out << j.dump() << (i + 1 < images.size() ? ",\n" : "\n");
    }
    out << "]}\n";
}

ImageScore score_image(const RealImageTruth& truth, const std::vector<TagDetection>& detections) {
    ImageScore s;
    s.tags = truth.tags;
    std::vector<int> matched;
    for (const auto& d : detections) {
        const bool known = std::find(truth.ids.begin(), truth.ids.end(), d.id) != truth.ids.end();
        const bool repeat = std::find(matched.begin(), matched.end(), d.id) != matched.end();
        const RealReference* ref = nullptr;
        for (const auto& r : truth.reference) {
            if (r.id == d.id) ref = &r;
        }
        bool placed = true;
        if (ref != nullptr) {
            Eigen::Vector2d centre = Eigen::Vector2d::Zero();
            for (const auto& c : ref->corners) centre += c / 4.0;
            placed = (d.centre - centre).norm() < 0.5 * (ref->corners[1] - ref->corners[0]).norm();
        }
        if (!known || repeat || !placed || s.found >= s.tags) {
            ++s.false_positives;
            continue;
        }
        matched.push_back(d.id);
        ++s.found;
        if (ref != nullptr) {
            for (double e : matched_corner_errors(d.corners, ref->corners)) s.corner_errors_px.push_back(e);
        }
    }
    return s;
}

void SetScore::add(const ImageScore& s) {
    tags += s.tags;
    found += s.found;
    false_positives += s.false_positives;
    corner_errors_px.insert(corner_errors_px.end(), s.corner_errors_px.begin(), s.corner_errors_px.end());
}

double SetScore::rate() const { return tags > 0 ? static_cast<double>(found - false_positives) / tags : 0.0; }

double SetScore::median_corner_error_px() const {
    if (corner_errors_px.empty()) return std::numeric_limits<double>::quiet_NaN();
    std::vector<double> e = corner_errors_px;
    std::nth_element(e.begin(), e.begin() + static_cast<std::ptrdiff_t>(e.size() / 2), e.end());
    return e[e.size() / 2];
}

std::filesystem::path tags_real_dir(const std::filesystem::path& fallback) {
    if (const char* env = std::getenv("MOGAO_TAGS_REAL_DIR"); env != nullptr && *env != '\0') return env;
    return fallback;
}

}  // namespace mogao
