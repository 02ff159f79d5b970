// SPDX-License-Identifier: Apache-2.0
#include "drivers/kms/drm_device.h"

#include <fcntl.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <system_error>

namespace mogao {
namespace {

std::string id_text(std::string_view what, std::uint32_t id) { return std::string(what) + " " + std::to_string(id); }

// libdrm returns either -1 or -errno; errno is set in both cases, so read it right after the call.
template <typename Ptr, typename Raw>
Result<Ptr> wrap(Raw* raw, std::string_view what) {
    if (raw == nullptr) return errno_error(what);
    return Ptr(raw);
}

}  // namespace

std::vector<std::filesystem::path> list_drm_cards(const std::filesystem::path& dir) {
    std::vector<std::pair<int, std::filesystem::path>> cards;
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
        const std::string name = entry.path().filename().string();
        if (name.rfind("card", 0) != 0 || name.size() == 4) continue;
        int number = 0;
        const auto [end, err] = std::from_chars(name.data() + 4, name.data() + name.size(), number);
        if (err != std::errc{} || end != name.data() + name.size()) continue;
        cards.emplace_back(number, entry.path());
    }
    std::sort(cards.begin(), cards.end());
    std::vector<std::filesystem::path> paths;
    for (auto& card : cards) paths.push_back(std::move(card.second));
    return paths;
}

std::string connector_name(const drmModeConnector& connector) {
    const char* type = drmModeGetConnectorTypeName(connector.connector_type);
    return std::string(type != nullptr ? type : "Unknown") + "-" + std::to_string(connector.connector_type_id);
}

Result<DrmDevice> DrmDevice::open(const std::filesystem::path& path) {
    UniqueFd fd(::open(path.c_str(), O_RDWR | O_CLOEXEC | O_NONBLOCK));
    if (!fd.valid()) return errno_error("open(" + path.string() + ")");
    DrmResources resources(drmModeGetResources(fd.get()));
    if (!resources) {
        return make_error(ENODEV, path.string() + " is not a KMS device (drmModeGetResources: " +
                                      std::strerror(errno != 0 ? errno : ENODEV) + ")");
    }
    return DrmDevice(std::move(fd), path);
}

Status DrmDevice::enable_client_caps(bool atomic) const {
    if (drmSetClientCap(fd(), DRM_CLIENT_CAP_UNIVERSAL_PLANES, 1) != 0) {
        return make_error(EOPNOTSUPP, path_.string() + ": no universal planes (DRM_CLIENT_CAP_UNIVERSAL_PLANES)");
    }
    if (atomic && drmSetClientCap(fd(), DRM_CLIENT_CAP_ATOMIC, 1) != 0) {
        return make_error(EOPNOTSUPP, path_.string() + ": no atomic modesetting (DRM_CLIENT_CAP_ATOMIC)");
    }
    return {};
}

Result<DrmResources> DrmDevice::resources() const {
    return wrap<DrmResources>(drmModeGetResources(fd()), "drmModeGetResources");
}
Result<DrmConnector> DrmDevice::connector(std::uint32_t id) const {
    return wrap<DrmConnector>(drmModeGetConnector(fd(), id), id_text("drmModeGetConnector", id));
}
Result<DrmEncoder> DrmDevice::encoder(std::uint32_t id) const {
    return wrap<DrmEncoder>(drmModeGetEncoder(fd(), id), id_text("drmModeGetEncoder", id));
}
Result<DrmCrtc> DrmDevice::crtc(std::uint32_t id) const {
    return wrap<DrmCrtc>(drmModeGetCrtc(fd(), id), id_text("drmModeGetCrtc", id));
}
Result<DrmPlaneResources> DrmDevice::plane_resources() const {
    return wrap<DrmPlaneResources>(drmModeGetPlaneResources(fd()), "drmModeGetPlaneResources");
}
Result<DrmPlane> DrmDevice::plane(std::uint32_t id) const {
    return wrap<DrmPlane>(drmModeGetPlane(fd(), id), id_text("drmModeGetPlane", id));
}

// ---- PropertyMap -------------------------------------------------------------------------------

Result<PropertyMap> PropertyMap::query(int fd, std::uint32_t object_id, std::uint32_t type) {
    DrmObjectProperties props(drmModeObjectGetProperties(fd, object_id, type));
    if (!props) return errno_error(id_text("drmModeObjectGetProperties", object_id));
    PropertyMap map;
    map.object_id_ = object_id;
    for (std::uint32_t i = 0; i < props->count_props; ++i) {
        DrmProperty prop(drmModeGetProperty(fd, props->props[i]));
        if (!prop) return errno_error(id_text("drmModeGetProperty", props->props[i]));
        map.entries_.push_back(Entry{prop->name, prop->prop_id, props->prop_values[i]});
    }
    return map;
}

const PropertyMap::Entry* PropertyMap::find(std::string_view name) const {
    const auto it = std::find_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.name == name; });
    return it == entries_.end() ? nullptr : &*it;
}

Result<std::uint32_t> PropertyMap::id(std::string_view name) const {
    if (const Entry* e = find(name)) return e->id;
    return make_error(ENOENT, id_text("KMS object", object_id_) + " has no property " + std::string(name));
}

Result<std::uint64_t> PropertyMap::value(std::string_view name) const {
    if (const Entry* e = find(name)) return e->value;
    return make_error(ENOENT, id_text("KMS object", object_id_) + " has no property " + std::string(name));
}

// ---- PropertyBlob ------------------------------------------------------------------------------

Result<PropertyBlob> PropertyBlob::create(int fd, const void* data, std::size_t size) {
    std::uint32_t id = 0;
    if (drmModeCreatePropertyBlob(fd, data, size, &id) != 0) return errno_error("drmModeCreatePropertyBlob");
    return PropertyBlob(fd, id);
}

}  // namespace mogao
