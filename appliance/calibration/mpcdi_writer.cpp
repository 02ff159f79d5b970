// SPDX-License-Identifier: Apache-2.0
#include "appliance/calibration/mpcdi_writer.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <set>

#include "appliance/calibration/mpcdi_error.h"
#include "appliance/calibration/mpcdi_xml.h"
#include "appliance/calibration/pfm_codec.h"
#include "appliance/calibration/png_codec.h"
#include "appliance/calibration/zip_archive.h"

namespace mogao {
namespace {

using Entries = std::vector<std::pair<std::string, std::vector<std::uint8_t>>>;

void fill_default_paths(MpcdiFile& file) {
    for (MpcdiBuffer& b : file.buffers) {
        for (MpcdiRegion& r : b.regions) {
            if (r.warp.path.empty()) r.warp.path = "GeometryWarpFile-" + r.id + ".pfm";
            if (r.alpha.path.empty()) r.alpha.path = "AlphaMap-" + r.id + ".png";
            if (r.beta && r.beta->path.empty()) r.beta->path = "BetaMap-" + r.id + ".png";
            if (r.distortion && r.distortion->path.empty()) r.distortion->path = "DistortionMapFile-" + r.id + ".pfm";
            if (r.response && r.response->path.empty()) r.response->path = response_lut_entry(r.id);
        }
    }
}

bool valid_resolution(ImageSize s) {
    return s.width >= 1 && s.height >= 1 && s.width <= kMaxMapDimension && s.height <= kMaxMapDimension;
}

// What read_mpcdi would reject must not be written: the same limits as the parser (mpcdi_xml.cpp).
void validate_numbers(const MpcdiRegion& r, const std::string& rw) {
    if (!valid_resolution(r.resolution)) {
        throw MpcdiError(rw + ": resolution is outside 1.." + std::to_string(kMaxMapDimension) + " per side");
    }
    const auto in = [](double v, double lo, double hi) { return v >= lo && v <= hi; };
    if (!in(r.x, 0.0, 1.0) || !in(r.y, 0.0, 1.0) || !in(r.xsize, 1e-9, 1.0) || !in(r.ysize, 1e-9, 1.0) ||
        r.x + r.xsize > 1.0 + 1e-5 || r.y + r.ysize > 1.0 + 1e-5) {
        throw MpcdiError(rw + ": x, y must be in [0, 1], xsize, ysize in (0, 1], and the region inside the buffer");
    }
    bool finite = true;
    if (r.frustum) {
        const MpcdiFrustum& f = *r.frustum;
        for (const double v : {f.yaw, f.pitch, f.roll, f.right_angle, f.left_angle, f.up_angle, f.down_angle}) {
            finite = finite && std::isfinite(v);
        }
    }
    if (r.coordinate_frame) {
        const MpcdiCoordinateFrame& c = *r.coordinate_frame;
        for (const auto* v : {&c.pos, &c.yaw, &c.pitch, &c.roll}) {
            for (const double x : *v) finite = finite && std::isfinite(x);
        }
    }
    if (!finite) throw MpcdiError(rw + ": frustum and coordinateFrame values must be finite");
}

void validate(const MpcdiFile& file, const std::string& who) {
    if (file.level < 1 || file.level > 4)
        throw MpcdiError(who + ": level " + std::to_string(file.level) + " is outside 1..4");
    if (file.version.rfind("1.", 0) != 0) throw MpcdiError(who + ": version \"" + file.version + "\" is not 1.x");
    if (file.buffers.empty()) throw MpcdiError(who + ": no buffer");
    std::set<std::string> ids;
    std::set<std::string> paths{"mpcdi.xml"};
    for (const MpcdiBuffer& b : file.buffers) {
        if (b.id.empty()) throw MpcdiError(who + ": buffer with an empty id");
        if (b.regions.empty()) throw MpcdiError(who + ": buffer '" + b.id + "' has no region");
        if (!valid_resolution(b.resolution)) {
            throw MpcdiError(who + ": buffer '" + b.id + "': resolution is outside 1.." +
                             std::to_string(kMaxMapDimension));
        }
        for (const MpcdiRegion& r : b.regions) {
            const std::string rw = who + ": region '" + r.id + "'";
            if (r.id.empty()) throw MpcdiError(who + ": region with an empty id");
            if (r.id.find_first_of("/\\") != std::string::npos) throw MpcdiError(rw + ": id contains '/' or '\\'");
            if (!ids.insert(r.id).second) throw MpcdiError(rw + ": id is used twice");
            validate_numbers(r, rw);
            if (!std::isfinite(r.alpha.gamma_embedded) || r.alpha.gamma_embedded < 0.0) {
                throw MpcdiError(rw + ": gammaEmbedded must be finite and >= 0");
            }
            const auto add_path = [&](const std::string& p) {
                require_safe_entry_name(p, rw);
                if (!paths.insert(p).second) throw MpcdiError(rw + ": entry name '" + p + "' is used twice");
            };
            add_path(r.warp.path);
            add_path(r.alpha.path);
            if (r.beta) add_path(r.beta->path);
            if (r.distortion) add_path(r.distortion->path);
            if (r.response) {
                if (r.response->path != response_lut_entry(r.id)) {
                    throw MpcdiError(rw + ": response LUT entry '" + r.response->path + "' must be named '" +
                                     response_lut_entry(r.id) + "' (the reader finds it by that name)");
                }
                add_path(r.response->path);
                check_response_lut(r.response->map, rw + ": response LUT");
            }
        }
    }
}

Entries encode_entries(const MpcdiFile& file, const std::string& who) {
    std::vector<const MpcdiRegion*> regions;
    for (const MpcdiBuffer& b : file.buffers) {
        for (const MpcdiRegion& r : b.regions) regions.push_back(&r);
    }
    std::sort(regions.begin(), regions.end(), [](const MpcdiRegion* a, const MpcdiRegion* b) { return a->id < b->id; });
    Entries entries;
    for (const MpcdiRegion* r : regions) {
        const auto entry = [&](const std::string& name) { return who + ": entry '" + name + "'"; };
        entries.emplace_back(r->warp.path, encode_pfm(r->warp.map, entry(r->warp.path)));
        entries.emplace_back(r->alpha.path, encode_png_map(r->alpha.map, entry(r->alpha.path)));
        if (r->beta) entries.emplace_back(r->beta->path, encode_png_map(r->beta->map, entry(r->beta->path)));
        if (r->distortion) {
            entries.emplace_back(r->distortion->path, encode_pfm(r->distortion->map, entry(r->distortion->path)));
        }
        if (r->response) {
            entries.emplace_back(r->response->path, encode_pfm(r->response->map, entry(r->response->path)));
        }
    }
    const std::string xml = print_mpcdi_xml(file);
    entries.emplace_back("mpcdi.xml", std::vector<std::uint8_t>(xml.begin(), xml.end()));
    return entries;
}

void fsync_path(const std::filesystem::path& p, int flags, const std::string& who) {
    const int fd = ::open(p.c_str(), flags | O_CLOEXEC);
    if (fd < 0) throw MpcdiError(who + ": cannot open '" + p.string() + "' to flush it: " + std::strerror(errno));
    const int rc = ::fsync(fd);
    const int saved = errno;
    ::close(fd);
    if (rc != 0) throw MpcdiError(who + ": fsync of '" + p.string() + "' failed: " + std::strerror(saved));
}

}  // namespace

void write_mpcdi(const std::filesystem::path& path, const MpcdiFile& input) {
    const std::string who = "write_mpcdi '" + path.string() + "'";
    MpcdiFile file = input;
    fill_default_paths(file);
    validate(file, who);
    const Entries entries = encode_entries(file, who);

    const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
    std::string temp = (dir / ("." + path.filename().string() + ".tmp-XXXXXX")).string();
    const int fd = ::mkstemp(temp.data());
    if (fd < 0)
        throw MpcdiError(who + ": cannot create a temporary file in '" + dir.string() + "': " + std::strerror(errno));
    // mkstemp creates 0600; a calibration is not secret and other users (the kiosk) must read it.
    const int chmod_rc = ::fchmod(fd, 0644);
    ::close(fd);
    try {
        if (chmod_rc != 0)
            throw MpcdiError(who + ": cannot set permissions of the temporary file: " + std::strerror(errno));
        write_zip(temp, entries, who);
        fsync_path(temp, O_RDONLY, who);
        std::error_code ec;
        std::filesystem::rename(temp, path, ec);
        if (ec) throw MpcdiError(who + ": cannot rename the temporary file into place: " + ec.message());
    } catch (...) {
        std::error_code ignored;
        std::filesystem::remove(temp, ignored);
        throw;
    }
    // Make the rename itself durable; failure here does not undo a complete write, so it is ignored.
    try {
        fsync_path(dir, O_RDONLY | O_DIRECTORY, who);
    } catch (const MpcdiError&) {}
}

}  // namespace mogao
