// SPDX-License-Identifier: Apache-2.0
#include "appliance/calibration/mpcdi_reader.h"

#include <set>

#include "appliance/calibration/mpcdi_error.h"
#include "appliance/calibration/mpcdi_xml.h"
#include "appliance/calibration/pfm_codec.h"
#include "appliance/calibration/png_codec.h"
#include "appliance/calibration/zip_archive.h"

namespace mogao {
namespace {

std::string entry_who(const std::string& who, const std::string& name) { return who + ": entry '" + name + "'"; }

PfmMap load_pfm(const ZipReader& zip, const std::string& who, const std::string& name) {
    require_safe_entry_name(name, who + ": mpcdi.xml path");
    const std::vector<std::uint8_t> bytes = zip.read(name);
    return decode_pfm(bytes, entry_who(who, name));
}

// `declared` carries the XML's componentDepth (channels) and bitDepth.
PngMap load_png(const ZipReader& zip, const std::string& who, const std::string& name, const PngMap& declared) {
    require_safe_entry_name(name, who + ": mpcdi.xml path");
    const std::vector<std::uint8_t> bytes = zip.read(name);
    PngMap map = decode_png_map(bytes, entry_who(who, name));
    if (map.channels != declared.channels || map.bit_depth != declared.bit_depth) {
        throw MpcdiError(entry_who(who, name) + ": PNG has " + std::to_string(map.channels) + " channel(s) of " +
                         std::to_string(map.bit_depth) + " bits but mpcdi.xml declares componentDepth " +
                         std::to_string(declared.channels) + ", bitDepth " + std::to_string(declared.bit_depth));
    }
    return map;
}

}  // namespace

MpcdiFile read_mpcdi(const std::filesystem::path& path, std::vector<std::string>* notes) {
    const std::string who = "read_mpcdi '" + path.string() + "'";
    const ZipReader zip(path, who);
    std::string xml_name = "mpcdi.xml";
    if (!zip.contains(xml_name)) {
        if (!zip.contains("mpacs.xml")) throw MpcdiError(who + ": no 'mpcdi.xml' entry (not an MPCDI file)");
        xml_name = "mpacs.xml";
        if (notes != nullptr) notes->push_back("descriptor entry is 'mpacs.xml' (pre-standard name)");
    }
    const std::vector<std::uint8_t> xml = zip.read(xml_name);
    MpcdiFile file =
        parse_mpcdi_xml(std::string_view(reinterpret_cast<const char*>(xml.data()), xml.size()), who, notes);

    std::set<std::string> used{xml_name};
    for (MpcdiBuffer& buffer : file.buffers) {
        for (MpcdiRegion& r : buffer.regions) {
            r.warp.map = load_pfm(zip, who, r.warp.path);
            r.alpha.map = load_png(zip, who, r.alpha.path, r.alpha.map);
            used.insert(r.warp.path);
            used.insert(r.alpha.path);
            if (r.beta) {
                r.beta->map = load_png(zip, who, r.beta->path, r.beta->map);
                used.insert(r.beta->path);
            }
            if (r.distortion) {
                r.distortion->map = load_pfm(zip, who, r.distortion->path);
                used.insert(r.distortion->path);
            }
            const std::string lut = response_lut_entry(r.id);
            if (zip.contains(lut)) {
                r.response = MpcdiResponseLut{lut, load_pfm(zip, who, lut)};
                check_response_lut(r.response->map, entry_who(who, lut));
                used.insert(lut);
            }
        }
    }
    if (notes != nullptr) {
        for (const std::string& name : zip.names()) {
            if (used.count(name) == 0)
                notes->push_back("entry '" + name + "' is not referenced by mpcdi.xml (ignored)");
        }
    }
    return file;
}

}  // namespace mogao
