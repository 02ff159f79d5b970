// SPDX-License-Identifier: Apache-2.0
// TagFamily: sole owner of one AprilTag 3 family (the code table apriltag_family_t), created by
// name. Move-only (UniqueHandle, common/unique_handle.h; a moved-from family owns nothing and
// get() is null). A family may be added to one detector only (AprilTag's rule), so each
// TagDetector owns its own TagFamily.
//
// Names (AprilTag 3.3 as shipped by Debian 12): tag36h11 (default: 587 codes, Hamming distance
// 11, the family the AprilTag authors recommend), tag25h9, tag16h5, tag36h10, tagCircle21h7,
// tagCircle49h12, tagCustom48h12, tagStandard41h12, tagStandard52h13.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "common/unique_handle.h"

struct apriltag_family;  // apriltag.h; kept out of this header

namespace mogao {

class TagFamily {
public:
    // Throws std::invalid_argument naming `name` and listing the known names.
    explicit TagFamily(std::string_view name);

    [[nodiscard]] const std::string& name() const { return name_; }
    [[nodiscard]] int code_count() const;          // valid ids are [0, code_count())
    [[nodiscard]] int total_width_cells() const;   // side of the whole tag bitmap incl. its outer border
    [[nodiscard]] int border_width_cells() const;  // side of the square the detector's corners lie on
    [[nodiscard]] apriltag_family* get() const { return family_.get().family; }

    [[nodiscard]] static const std::vector<std::string>& known_names();

private:
    // Each family has its own tagXXX_destroy, so the family moves together with it.
    struct Owned {
        apriltag_family* family = nullptr;
        void (*destroy)(apriltag_family*) = nullptr;
        bool operator==(const Owned&) const = default;
    };
    struct Traits {
        using Value = Owned;
        static constexpr Owned null() noexcept { return {}; }
        static void close(Owned owned) noexcept { owned.destroy(owned.family); }
    };

    std::string name_;
    UniqueHandle<Traits> family_;
};

}  // namespace mogao
