// SPDX-License-Identifier: Apache-2.0
#include "appliance/calibration/mpcdi_xml.h"

#include <tinyxml2.h>

#include <cmath>
#include <ctime>
#include <map>
#include <optional>
#include <set>

#include "appliance/calibration/mpcdi_error.h"
#include "appliance/calibration/mpcdi_number.h"
#include "appliance/calibration/pfm_codec.h"

namespace mogao {
namespace {

using tinyxml2::XMLElement;

// Context for messages: "<region id="proj1">".
std::string tag(const XMLElement* e) {
    std::string t = "<" + std::string(e->Name());
    if (const char* id = e->Attribute("id")) t += " id=\"" + std::string(id) + "\"";
    if (const char* r = e->Attribute("region")) t += " region=\"" + std::string(r) + "\"";
    return t + ">";
}

class Parser {
public:
    Parser(std::string who, std::vector<std::string>* notes) : who_(std::move(who) + ": mpcdi.xml"), notes_(notes) {}

    [[noreturn]] void fail(const XMLElement* e, const std::string& why) const {
        throw MpcdiError(who_ + ": " +
                         (e != nullptr ? tag(e) + " (line " + std::to_string(e->GetLineNum()) + "): " : "") + why);
    }
    void note(const std::string& text) const {
        if (notes_ != nullptr) notes_->push_back(text);
    }

    std::string attr(const XMLElement* e, const char* name) const {
        const char* v = e->Attribute(name);
        if (v == nullptr) fail(e, std::string("missing attribute '") + name + "'");
        return v;
    }
    int int_attr(const XMLElement* e, const char* name, int lo, int hi) const {
        const std::string text = attr(e, name);
        const std::optional<int> v = parse_int(text);
        if (!v || *v < lo || *v > hi) {
            fail(e, std::string("attribute ") + name + "=\"" + text + "\" is not an integer in [" + std::to_string(lo) +
                        ", " + std::to_string(hi) + "]");
        }
        return *v;
    }
    double number_attr(const XMLElement* e, const char* name, double lo, double hi) const {
        const std::string text = attr(e, name);
        const std::optional<double> v = parse_number(text);
        if (!v || *v < lo || *v > hi) {
            fail(e, std::string("attribute ") + name + "=\"" + text + "\" is not a number in [" + format_number(lo) +
                        ", " + format_number(hi) + "]");
        }
        return *v;
    }
    const XMLElement* child(const XMLElement* e, const char* name) const {
        const XMLElement* c = e->FirstChildElement(name);
        if (c == nullptr) fail(e, std::string("missing child element <") + name + ">");
        return c;
    }
    std::string text(const XMLElement* e, const char* name) const {
        const char* t = child(e, name)->GetText();
        return t == nullptr ? std::string() : std::string(t);
    }
    std::string nonempty_text(const XMLElement* e, const char* name) const {
        std::string t = text(e, name);
        if (t.empty()) fail(e, std::string("<") + name + "> is empty");
        return t;
    }
    double number(const XMLElement* e, const char* name) const {
        const std::string t = text(e, name);
        const std::optional<double> v = parse_number(t);
        if (!v) fail(e, std::string("<") + name + ">" + t + "</" + name + "> is not a finite number");
        return *v;
    }
    int int_text(const XMLElement* e, const char* name, std::initializer_list<int> allowed) const {
        const std::string t = text(e, name);
        const std::optional<int> v = parse_int(t);
        for (const int a : allowed) {
            if (v && *v == a) return a;
        }
        std::string list;
        for (const int a : allowed) list += (list.empty() ? "" : ", ") + std::to_string(a);
        fail(e, std::string("<") + name + ">" + t + "</" + name + "> is not one of " + list);
    }

    template <typename Enum, std::size_t N>
    std::optional<Enum> lookup(const std::string& t, const std::array<Enum, N>& values) const {
        // "unkown" is how reference-library versions before commit 1ddbc9a spelled "unknown".
        const std::string key = t == "unkown" ? "unknown" : t;
        for (const Enum v : values) {
            if (to_string(v) == key) return v;
        }
        return std::nullopt;
    }
    template <typename Enum, std::size_t N>
    Enum enum_text(const XMLElement* e, const char* name, const std::array<Enum, N>& values) const {
        const std::string t = text(e, name);
        if (const auto v = lookup(t, values)) return *v;
        std::string list;
        for (const Enum v : values) list += (list.empty() ? "" : ", ") + std::string(to_string(v));
        fail(e, std::string("<") + name + ">" + t + "</" + name + "> is not one of " + list);
    }

    MpcdiFile parse(std::string_view xml) {
        tinyxml2::XMLDocument doc;
        if (doc.Parse(xml.data(), xml.size()) != tinyxml2::XML_SUCCESS) {
            throw MpcdiError(who_ + ": not well-formed XML: " + doc.ErrorStr());
        }
        const XMLElement* root = doc.RootElement();
        if (root == nullptr || std::string_view(root->Name()) != "MPCDI") {
            throw MpcdiError(who_ + ": root element is not <MPCDI>");
        }
        MpcdiFile file;
        const std::string profile = attr(root, "profile");
        const std::array profiles{MpcdiProfile::two_d, MpcdiProfile::three_d, MpcdiProfile::advanced_3d,
                                  MpcdiProfile::shader_lamp};
        const auto p = lookup(profile, profiles);
        if (!p) fail(root, "attribute profile=\"" + profile + "\" is not one of 2d, 3d, a3, sl");
        file.profile = *p;
        file.version = attr(root, "version");
        if (file.version != "1.0" && file.version.rfind("1.", 0) != 0) {
            fail(root, "version \"" + file.version + "\" is not supported (MPCDI v1.x only)");
        }
        file.level = int_attr(root, "level", 1, 4);
        if (const char* date = root->Attribute("date")) {
            file.date = date;
        } else {
            note("<MPCDI> has no date attribute");
        }

        const XMLElement* display = child(root, "display");
        for (const XMLElement* b = display->FirstChildElement(); b != nullptr; b = b->NextSiblingElement()) {
            if (std::string_view(b->Name()) != "buffer") fail(b, "unexpected element in <display> (only <buffer>)");
            file.buffers.push_back(parse_buffer(b));
        }
        if (file.buffers.empty()) fail(display, "no <buffer>");
        parse_files(root, file);
        return file;
    }

    MpcdiBuffer parse_buffer(const XMLElement* b) {
        MpcdiBuffer buffer;
        buffer.id = attr(b, "id");
        buffer.resolution = {int_attr(b, "Xresolution", 1, kMaxMapDimension),
                             int_attr(b, "Yresolution", 1, kMaxMapDimension)};
        for (const XMLElement* r = b->FirstChildElement(); r != nullptr; r = r->NextSiblingElement()) {
            if (std::string_view(r->Name()) != "region") fail(r, "unexpected element in <buffer> (only <region>)");
            buffer.regions.push_back(parse_region(r));
        }
        if (buffer.regions.empty()) fail(b, "no <region>");
        return buffer;
    }

    MpcdiRegion parse_region(const XMLElement* r) {
        MpcdiRegion region;
        region.id = attr(r, "id");
        if (!region_ids_.insert(region.id).second) fail(r, "region id is used twice");
        region.resolution = {int_attr(r, "Xresolution", 1, kMaxMapDimension),
                             int_attr(r, "Yresolution", 1, kMaxMapDimension)};
        region.x = number_attr(r, "x", 0.0, 1.0);
        region.y = number_attr(r, "y", 0.0, 1.0);
        // Sizes up to 1; x + xsize may pass 1 by the 6-digit rounding of "%g" (0.666667 + 0.333334).
        region.xsize = number_attr(r, "xsize", 1e-9, 1.0);
        region.ysize = number_attr(r, "ysize", 1e-9, 1.0);
        if (region.x + region.xsize > 1.0 + 1e-5 || region.y + region.ysize > 1.0 + 1e-5) {
            fail(r, "region extends past the buffer (x + xsize or y + ysize > 1)");
        }
        if (const XMLElement* f = r->FirstChildElement("frustum")) {
            region.frustum = MpcdiFrustum{number(f, "yaw"),        number(f, "pitch"),     number(f, "roll"),
                                          number(f, "rightAngle"), number(f, "leftAngle"), number(f, "upAngle"),
                                          number(f, "downAngle")};
        }
        if (const XMLElement* c = r->FirstChildElement("coordinateFrame")) {
            MpcdiCoordinateFrame frame;
            const auto vec = [&](const char* stem) {
                const std::string s(stem);
                return std::array<double, 3>{number(c, (s + "x").c_str()), number(c, (s + "y").c_str()),
                                             number(c, (s + "z").c_str())};
            };
            frame.pos = vec("pos");
            frame.yaw = vec("yaw");
            frame.pitch = vec("pitch");
            frame.roll = vec("roll");
            region.coordinate_frame = frame;
        }
        return region;
    }

    void parse_files(const XMLElement* root, MpcdiFile& file) {
        std::map<std::string, MpcdiRegion*> regions;
        for (MpcdiBuffer& b : file.buffers) {
            for (MpcdiRegion& r : b.regions) regions[r.id] = &r;
        }
        std::set<std::string> done;
        const XMLElement* files = child(root, "files");
        for (const XMLElement* fs = files->FirstChildElement(); fs != nullptr; fs = fs->NextSiblingElement()) {
            if (std::string_view(fs->Name()) != "fileset") fail(fs, "unexpected element in <files> (only <fileset>)");
            const std::string id = attr(fs, "region");
            const auto it = regions.find(id);
            if (it == regions.end()) fail(fs, "no <region> has id \"" + id + "\"");
            if (!done.insert(id).second) fail(fs, "second <fileset> for the same region");
            parse_fileset(fs, *it->second);
        }
        for (const auto& [id, region] : regions) {
            if (done.count(id) == 0) fail(files, "no <fileset> for region \"" + id + "\"");
        }
    }

    void parse_fileset(const XMLElement* fs, MpcdiRegion& region) {
        const XMLElement* w = child(fs, "geometryWarpFile");
        region.warp.path = nonempty_text(w, "path");
        region.warp.geometric_unit =
            enum_text(w, "geometricUnit",
                      std::array{GeometricUnit::mm, GeometricUnit::cm, GeometricUnit::dm, GeometricUnit::m,
                                 GeometricUnit::in, GeometricUnit::ft, GeometricUnit::yd, GeometricUnit::unknown});
        const std::string interpolation = text(w, "interpolation");
        region.warp.interpolation = enum_text(w, "interpolation",
                                              std::array{WarpInterpolation::linear, WarpInterpolation::keystone,
                                                         WarpInterpolation::smooth, WarpInterpolation::unknown});
        region.warp.origin_of_3d_data = parse_origin(w, region.id, interpolation);

        const XMLElement* a = child(fs, "alphaMap");
        region.alpha.path = nonempty_text(a, "path");
        region.alpha.map.channels = int_text(a, "componentDepth", {1, 3});
        region.alpha.map.bit_depth = int_text(a, "bitDepth", {8, 16});
        region.alpha.gamma_embedded = number(a, "gammaEmbedded");
        if (region.alpha.gamma_embedded < 0.0 || region.alpha.gamma_embedded > 10.0) {
            fail(a, "<gammaEmbedded> " + format_number(region.alpha.gamma_embedded) + " is outside [0, 10]");
        }
        if (region.alpha.gamma_embedded == 0.0) {
            note("region \"" + region.id + "\": <gammaEmbedded>0 (not recorded by the writer; conversions assume 2.2)");
        }
        if (const XMLElement* b = fs->FirstChildElement("betaMap")) {
            MpcdiBetaMap beta;
            beta.path = nonempty_text(b, "path");
            beta.map.channels = int_text(b, "componentDepth", {1, 3});
            beta.map.bit_depth = int_text(b, "bitDepth", {8, 16});
            region.beta = beta;
        }
        if (const XMLElement* d = fs->FirstChildElement("distortionMap")) {
            region.distortion = MpcdiDistortionMap{nonempty_text(d, "path"), {}};
        }
    }

    OriginOf3DData parse_origin(const XMLElement* w, const std::string& region_id,
                                const std::string& interpolation) const {
        const XMLElement* o = w->FirstChildElement("originOf3DData");
        if (o == nullptr) o = w->FirstChildElement("originof3DData");
        if (o == nullptr) fail(w, "missing child element <originof3DData> (or <originOf3DData>)");
        const std::string t = o->GetText() == nullptr ? std::string() : std::string(o->GetText());
        const std::array origins{OriginOf3DData::center_of_mass, OriginOf3DData::ideal_eye_point,
                                 OriginOf3DData::floor_center, OriginOf3DData::unknown};
        if (const auto v = lookup(t, origins)) return *v;
        if (t == interpolation) {
            note("region \"" + region_id + "\": <originof3DData>" + t +
                 " repeats <interpolation> (reference writer bug): read as unknown");
            return OriginOf3DData::unknown;
        }
        fail(o, "\"" + t + "\" is not one of centerOfMass, idealEyePoint, floorCenter, unknown");
    }

private:
    std::string who_;
    std::vector<std::string>* notes_;
    std::set<std::string> region_ids_;
};

std::string escape(std::string_view s) {
    std::string out;
    for (const char c : s) {
        switch (c) {
            case '&':
                out += "&amp;";
                break;
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '"':
                out += "&quot;";
                break;
            case '\'':
                out += "&apos;";
                break;
            default:
                out += c;
        }
    }
    return out;
}

std::string utc_now() {
    const std::time_t now = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&now, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
    return buf;
}

class Printer {
public:
    void line(int depth, const std::string& text) {
        out_ += std::string(static_cast<std::size_t>(depth) * 4, ' ') + text + "\n";
    }
    void value(int depth, const char* name, const std::string& text) {
        line(depth, "<" + std::string(name) + ">" + escape(text) + "</" + name + ">");
    }
    void number(int depth, const char* name, double v) { value(depth, name, format_number(v)); }
    std::string take() { return std::move(out_); }

private:
    std::string out_;
};

}  // namespace

MpcdiFile parse_mpcdi_xml(std::string_view text, const std::string& who, std::vector<std::string>* notes) {
    return Parser(who, notes).parse(text);
}

namespace {

// A region's <frustum> and <coordinateFrame> (whichever it has), inside its <region> element.
void print_region_placement(Printer& p, const MpcdiRegion& r) {
    if (r.frustum) {
        const MpcdiFrustum& f = *r.frustum;
        p.line(4, "<frustum>");
        p.number(5, "yaw", f.yaw);
        p.number(5, "pitch", f.pitch);
        p.number(5, "roll", f.roll);
        p.number(5, "rightAngle", f.right_angle);
        p.number(5, "leftAngle", f.left_angle);
        p.number(5, "upAngle", f.up_angle);
        p.number(5, "downAngle", f.down_angle);
        p.line(4, "</frustum>");
    }
    if (r.coordinate_frame) {
        const MpcdiCoordinateFrame& c = *r.coordinate_frame;
        p.line(4, "<coordinateFrame>");
        const auto vec = [&](const char* stem, const std::array<double, 3>& v) {
            const char* axes[3] = {"x", "y", "z"};
            for (std::size_t i = 0; i < 3; ++i) p.number(5, (std::string(stem) + axes[i]).c_str(), v[i]);
        };
        vec("pos", c.pos);
        vec("yaw", c.yaw);
        vec("pitch", c.pitch);
        vec("roll", c.roll);
        p.line(4, "</coordinateFrame>");
    }
}

// A region's <fileset>: its warp, alpha and optional beta and distortion maps' files.
void print_fileset(Printer& p, const MpcdiRegion& r) {
    p.line(2, "<fileset region=\"" + escape(r.id) + "\">");
    p.line(3, "<geometryWarpFile>");
    p.value(4, "path", r.warp.path);
    p.value(4, "geometricUnit", std::string(to_string(r.warp.geometric_unit)));
    p.value(4, "interpolation", std::string(to_string(r.warp.interpolation)));
    p.value(4, "originof3DData", std::string(to_string(r.warp.origin_of_3d_data)));
    p.line(3, "</geometryWarpFile>");
    p.line(3, "<alphaMap>");
    p.value(4, "path", r.alpha.path);
    p.value(4, "componentDepth", std::to_string(r.alpha.map.channels));
    p.value(4, "bitDepth", std::to_string(r.alpha.map.bit_depth));
    p.number(4, "gammaEmbedded", r.alpha.gamma_embedded);
    p.line(3, "</alphaMap>");
    if (r.beta) {
        p.line(3, "<betaMap>");
        p.value(4, "path", r.beta->path);
        p.value(4, "bitDepth", std::to_string(r.beta->map.bit_depth));  // reference order: bitDepth first
        p.value(4, "componentDepth", std::to_string(r.beta->map.channels));
        p.line(3, "</betaMap>");
    }
    if (r.distortion) {
        p.line(3, "<distortionMap>");
        p.value(4, "path", r.distortion->path);
        p.line(3, "</distortionMap>");
    }
    p.line(2, "</fileset>");
}

}  // namespace

std::string print_mpcdi_xml(const MpcdiFile& file) {
    Printer p;
    p.line(0, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>");
    p.line(0, "<MPCDI profile=\"" + std::string(to_string(file.profile)) + "\" date=\"" +
                  escape(file.date.empty() ? utc_now() : file.date) + "\" level=\"" + std::to_string(file.level) +
                  "\" version=\"" + escape(file.version) + "\">");
    p.line(1, "<display>");
    for (const MpcdiBuffer& b : file.buffers) {
        p.line(2, "<buffer id=\"" + escape(b.id) + "\" Xresolution=\"" + std::to_string(b.resolution.width) +
                      "\" Yresolution=\"" + std::to_string(b.resolution.height) + "\">");
        for (const MpcdiRegion& r : b.regions) {
            const std::string open = "<region id=\"" + escape(r.id) + "\" Xresolution=\"" +
                                     std::to_string(r.resolution.width) + "\" Yresolution=\"" +
                                     std::to_string(r.resolution.height) + "\" x=\"" + format_number(r.x) + "\" y=\"" +
                                     format_number(r.y) + "\" xsize=\"" + format_number(r.xsize) + "\" ysize=\"" +
                                     format_number(r.ysize) + "\"";
            if (!r.frustum && !r.coordinate_frame) {
                p.line(3, open + "/>");
                continue;
            }
            p.line(3, open + ">");
            print_region_placement(p, r);
            p.line(3, "</region>");
        }
        p.line(2, "</buffer>");
    }
    p.line(1, "</display>");
    p.line(1, "<files>");
    for (const MpcdiBuffer& b : file.buffers) {
        for (const MpcdiRegion& r : b.regions) {
            print_fileset(p, r);
        }
    }
    p.line(1, "</files>");
    p.line(0, "</MPCDI>");
    return p.take();
}

}  // namespace mogao
