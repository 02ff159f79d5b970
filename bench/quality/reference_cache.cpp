// SPDX-License-Identifier: Apache-2.0
#include "bench/quality/reference_cache.h"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace mogao::quality {
namespace {

constexpr std::string_view kMagic = "mogao-quality-reference 1";

Error bad(const std::filesystem::path& file, const std::string& why) {
    return make_error(EINVAL, "reference cache " + file.string() + ": " + why);
}

}  // namespace

std::uint64_t fnv1a64(std::string_view text) {
    std::uint64_t h = 0xcbf29ce484222325ull;
    for (const char c : text) {
        h ^= static_cast<unsigned char>(c);
        h *= 0x100000001b3ull;
    }
    return h;
}

std::string cache_key(std::string_view description) {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(fnv1a64(description)));
    return buf;
}

RgbFloatImage reference_image(const CachedReference& ref) {
    RgbFloatImage out(ref.half_a.size);
    for (std::size_t i = 0; i < out.pixels.size(); ++i)
        out.pixels[i] = 0.5f * (ref.half_a.pixels[i] + ref.half_b.pixels[i]);
    return out;
}

std::filesystem::path default_cache_dir() {
    if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg != nullptr && *xdg != '\0')
        return std::filesystem::path(xdg) / "mogao" / "quality";
    const char* home = std::getenv("HOME");
    return std::filesystem::path(home != nullptr ? home : "/tmp") / ".cache" / "mogao" / "quality";
}

Status save_reference(const std::filesystem::path& file, const CachedReference& ref) {
    std::error_code ec;
    std::filesystem::create_directories(file.parent_path(), ec);
    const std::filesystem::path tmp = file.string() + ".tmp";
    {
        std::ofstream out(tmp, std::ios::binary);
        if (!out) return errno_error("cannot write " + tmp.string());
        out << kMagic << "\nkey " << cache_key(ref.description) << "\nspp_per_half " << ref.spp_per_half << "\nseconds "
            << ref.seconds << "\nsize " << ref.half_a.size.width << ' ' << ref.half_a.size.height << "\ndescription "
            << ref.description.size() << '\n'
            << ref.description << '\n';
        for (const RgbFloatImage* half : {&ref.half_a, &ref.half_b})
            out.write(reinterpret_cast<const char*>(half->pixels.data()),
                      static_cast<std::streamsize>(half->pixels.size() * sizeof(float)));
        if (!out.flush()) return errno_error("cannot write " + tmp.string());
    }
    std::filesystem::rename(tmp, file, ec);
    if (ec) return make_error(ec.value(), "cannot rename " + tmp.string() + ": " + ec.message());
    return {};
}

Result<CachedReference> load_reference(const std::filesystem::path& file, std::string_view expected_description) {
    std::ifstream in(file, std::ios::binary);
    if (!in) return errno_error("cannot read " + file.string());
    std::string magic, word, key;
    std::getline(in, magic);
    if (magic != kMagic) return bad(file, "not a reference file (first line '" + magic + "')");
    CachedReference ref;
    int w = 0, h = 0;
    std::size_t description_bytes = 0;
    in >> word >> key;
    if (word != "key") return bad(file, "missing key");
    const std::string expected = cache_key(expected_description);
    if (key != expected) return bad(file, "stale: key " + key + " is not the expected " + expected);
    in >> word >> ref.spp_per_half >> word >> ref.seconds >> word >> w >> h >> word >> description_bytes;
    if (!in || word != "description" || ref.spp_per_half < 1 || w < 1 || h < 1 || w > 16384 || h > 16384)
        return bad(file, "malformed header");
    in.get();
    ref.description.resize(description_bytes);
    in.read(ref.description.data(), static_cast<std::streamsize>(description_bytes));
    in.get();
    if (ref.description != expected_description) return bad(file, "stale: description differs (hash collision)");
    for (RgbFloatImage* half : {&ref.half_a, &ref.half_b}) {
        *half = RgbFloatImage({w, h});
        in.read(reinterpret_cast<char*>(half->pixels.data()),
                static_cast<std::streamsize>(half->pixels.size() * sizeof(float)));
    }
    if (!in || in.peek() != std::char_traits<char>::eof()) return bad(file, "truncated or trailing data");
    return ref;
}

}  // namespace mogao::quality
