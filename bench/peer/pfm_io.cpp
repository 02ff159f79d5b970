// SPDX-License-Identifier: Apache-2.0
#include "bench/peer/pfm_io.h"

#include <cerrno>
#include <fstream>
#include <string>

namespace mogao::peer {

Status write_pfm(const std::filesystem::path& file, const RgbFloatImage& image) {
    std::ofstream out(file, std::ios::binary);
    if (!out) return errno_error("cannot write " + file.string());
    out << "PF\n" << image.size.width << ' ' << image.size.height << "\n-1.0\n";
    const auto row_bytes = static_cast<std::streamsize>(static_cast<std::size_t>(image.size.width) * 3 * sizeof(float));
    for (int y = image.size.height - 1; y >= 0; --y)  // PFM rows run bottom up
        out.write(reinterpret_cast<const char*>(image.at(0, y)), row_bytes);
    if (!out.flush()) return errno_error("cannot write " + file.string());
    return {};
}

Result<RgbFloatImage> read_pfm(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) return errno_error("cannot read " + file.string());
    std::string magic;
    int width = 0, height = 0;
    double scale = 0.0;
    in >> magic >> width >> height >> scale;
    if (!in || magic != "PF" || width < 1 || height < 1 || width > 1 << 15 || height > 1 << 15)
        return make_error(EINVAL, file.string() + ": not a colour PFM (want \"PF\", 1..32768 x 1..32768)");
    if (scale >= 0.0) return make_error(EINVAL, file.string() + ": big-endian PFM (positive scale) is not supported");
    in.get();  // the single whitespace byte after the scale
    RgbFloatImage image(ImageSize{width, height});
    const auto row_bytes = static_cast<std::streamsize>(static_cast<std::size_t>(width) * 3 * sizeof(float));
    for (int y = height - 1; y >= 0; --y) {
        if (!in.read(reinterpret_cast<char*>(image.at(0, y)), row_bytes))
            return make_error(EINVAL, file.string() + ": truncated (fewer than W*H*3 floats)");
    }
    return image;
}

}  // namespace mogao::peer
