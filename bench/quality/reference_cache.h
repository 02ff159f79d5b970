// SPDX-License-Identifier: Apache-2.0
// Converged references for the quality curves, cached on disk so the curves run in minutes
// (docs/quality.md, "References").
//
// A reference is kept as two independent halves (disjoint seeds, equal spp each) of linear radiance:
// their mean is the reference, and their difference measures its noise floor (reference_floor).
// The cache file is keyed by a description of everything the image depends on (scene file text,
// camera, size, reference knobs, renderer source version): key = FNV-1a 64 of that text
// (Fowler, Noll, Vo; IETF draft-eastlake-fnv). load_reference refuses a file whose key is not the
// expected one (stale: the scene, view or renderer changed), naming both keys, so a stale reference
// is never compared against; a truncated or foreign file is refused likewise. All errors are EINVAL
// (content) or errno values (I/O), messages name the file.
//
// File layout (little-endian host floats): "mogao-quality-reference 1\n", "key <16 hex>\n",
// "spp_per_half <n>\n", "seconds <wall s>\n", "size <W> <H>\n", "description <bytes>\n<text>\n",
// then W*H*3 floats of half A and W*H*3 floats of half B (each the mean of its samples).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "common/image.h"
#include "common/result.h"

namespace mogao::quality {

struct CachedReference {
    std::string description;  // what the key was made from (kept for messages)
    int spp_per_half = 0;     // samples per pixel in each half; the reference has twice that
    double seconds = 0.0;     // wall seconds spent rendering both halves (all threads)
    RgbFloatImage half_a, half_b;
};

[[nodiscard]] std::uint64_t fnv1a64(std::string_view text);
[[nodiscard]] std::string cache_key(std::string_view description);  // 16 lower-case hex digits

// The reference image: the mean of the two halves.
[[nodiscard]] RgbFloatImage reference_image(const CachedReference& ref);

// The cache folder: $XDG_CACHE_HOME/mogao/quality, else $HOME/.cache/mogao/quality.
[[nodiscard]] std::filesystem::path default_cache_dir();

[[nodiscard]] Status save_reference(const std::filesystem::path& file, const CachedReference& ref);

// Reads `file`; EINVAL naming both keys when its key is not cache_key(expected_description).
[[nodiscard]] Result<CachedReference> load_reference(const std::filesystem::path& file,
                                                     std::string_view expected_description);

}  // namespace mogao::quality
