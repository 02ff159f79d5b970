// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/tag_family.h"

#include <apriltag.h>
#include <tag16h5.h>
#include <tag25h9.h>
#include <tag36h10.h>
#include <tag36h11.h>
#include <tagCircle21h7.h>
#include <tagCircle49h12.h>
#include <tagCustom48h12.h>
#include <tagStandard41h12.h>
#include <tagStandard52h13.h>

#include <stdexcept>

namespace mogao {
namespace {

struct FamilyEntry {
    const char* name;
    apriltag_family_t* (*create)();
    void (*destroy)(apriltag_family_t*);
};

// The C headers declare `create()` without `void`, which C++ reads as taking no arguments.
constexpr FamilyEntry kFamilies[] = {
    {"tag36h11", tag36h11_create, tag36h11_destroy},
    {"tag25h9", tag25h9_create, tag25h9_destroy},
    {"tag16h5", tag16h5_create, tag16h5_destroy},
    {"tag36h10", tag36h10_create, tag36h10_destroy},
    {"tagCircle21h7", tagCircle21h7_create, tagCircle21h7_destroy},
    {"tagCircle49h12", tagCircle49h12_create, tagCircle49h12_destroy},
    {"tagCustom48h12", tagCustom48h12_create, tagCustom48h12_destroy},
    {"tagStandard41h12", tagStandard41h12_create, tagStandard41h12_destroy},
    {"tagStandard52h13", tagStandard52h13_create, tagStandard52h13_destroy},
};

}  // namespace

const std::vector<std::string>& TagFamily::known_names() {
    static const std::vector<std::string> names = [] {
        std::vector<std::string> v;
        for (const auto& f : kFamilies) v.emplace_back(f.name);
        return v;
    }();
    return names;
}

TagFamily::TagFamily(std::string_view name) : name_(name) {
    for (const auto& f : kFamilies) {
        if (name == f.name) {
            apriltag_family_t* family = f.create();
            if (family == nullptr) throw std::runtime_error("AprilTag could not allocate family " + name_);
            family_.reset(Owned{family, f.destroy});
            return;
        }
    }
    std::string list;
    for (const auto& n : known_names()) list += (list.empty() ? "" : ", ") + n;
    throw std::invalid_argument("tag family '" + name_ + "' is unknown; known: " + list);
}

int TagFamily::code_count() const { return static_cast<int>(get()->ncodes); }
int TagFamily::total_width_cells() const { return get()->total_width; }
int TagFamily::border_width_cells() const { return get()->width_at_border; }

}  // namespace mogao
