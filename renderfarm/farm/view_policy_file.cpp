// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/view_policy_file.h"

#include <fstream>
#include <set>
#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace mogao {
namespace {

using nlohmann::json;

struct Reader {
    std::string file;

    [[noreturn]] void fail(const std::string& where, const std::string& what) const {
        throw std::runtime_error(fmt::format("{}: {}: {}", file, where, what));
    }
    void only_keys(const json& object, const std::string& where, const std::set<std::string>& known) const {
        if (!object.is_object()) fail(where, "expected an object");
        for (const auto& [key, value] : object.items()) {
            if (!known.contains(key)) {
                std::string list;
                for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
                fail(where + "." + key, "unknown key (known: " + list + ")");
            }
        }
    }
    [[nodiscard]] double number(const json& j, const std::string& where) const {
        if (!j.is_number()) fail(where, "expected a number");
        return j.get<double>();
    }
    [[nodiscard]] CylinderScreen screen(const json& j, const std::string& where) const {
        only_keys(j, where, {"radius_m", "arc_deg", "bottom_m", "top_m", "eye_height_m"});
        for (const char* required : {"radius_m", "arc_deg", "bottom_m", "top_m"}) {
            if (!j.contains(required)) fail(where + "." + required, "missing");
        }
        CylinderScreen s;
        s.radius_m = number(j["radius_m"], where + ".radius_m");
        s.arc_deg = number(j["arc_deg"], where + ".arc_deg");
        s.bottom_m = number(j["bottom_m"], where + ".bottom_m");
        s.top_m = number(j["top_m"], where + ".top_m");
        s.eye_m = {0.0, j.contains("eye_height_m") ? number(j["eye_height_m"], where + ".eye_height_m") : 1.6, 0.0};
        return s;
    }
    [[nodiscard]] ImageSize size(const json& j, const std::string& where) const {
        if (!j.is_array() || j.size() != 2 || !j[0].is_number_integer() || !j[1].is_number_integer())
            fail(where, "expected [width, height] in pixels");
        return {j[0].get<int>(), j[1].get<int>()};
    }
    [[nodiscard]] ViewPolicy policy(const json& j, const std::string& where, ViewPolicy p) const {
        only_keys(j, where, {"screen", "max_guard_deg", "max_size", "visitable_area", "min_fov_deg"});
        if (j.contains("screen")) p.screen = screen(j["screen"], where + ".screen");
        if (j.contains("max_guard_deg")) p.max_guard_deg = number(j["max_guard_deg"], where + ".max_guard_deg");
        if (j.contains("max_size")) p.max_size = size(j["max_size"], where + ".max_size");
        if (j.contains("min_fov_deg")) p.min_fov_deg = number(j["min_fov_deg"], where + ".min_fov_deg");
        if (j.contains("visitable_area")) {
            if (!j["visitable_area"].is_boolean()) fail(where + ".visitable_area", "expected true or false");
            p.visitable_area = j["visitable_area"].get<bool>();
        }
        try {
            p.validate();
        } catch (const std::invalid_argument& e) {
            fail(where, e.what());
        }
        return p;
    }
};

}  // namespace

const ViewPolicy& ViewPolicies::of(const std::string& appliance) const {
    const auto it = appliances.find(appliance);
    return it == appliances.end() ? farm : it->second;
}

ViewPolicies read_view_policies(const std::filesystem::path& file, const ViewPolicy& farm) {
    const Reader r{file.string()};
    std::ifstream in(file);
    if (!in) r.fail("file", "cannot be read");
    json root;
    try {
        root = json::parse(in);
    } catch (const json::parse_error& e) {
        r.fail("file", std::string("not JSON: ") + e.what());
    }
    r.only_keys(root, "(top level)", {"appliances"});
    ViewPolicies out{farm, {}};
    if (!root.contains("appliances")) return out;
    const json& list = root["appliances"];
    if (!list.is_object()) r.fail("appliances", "expected an object of certificate names");
    for (const auto& [name, entry] : list.items()) {
        if (name.empty() || name.size() > 64) r.fail("appliances", "a certificate name must have 1..64 characters");
        out.appliances.emplace(name, r.policy(entry, "appliances." + name, farm));
    }
    return out;
}

}  // namespace mogao
