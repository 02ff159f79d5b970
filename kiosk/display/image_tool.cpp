// SPDX-License-Identifier: Apache-2.0
// mogao_kiosk_image_tool: image checks for the kiosk's end-to-end scripts (not installed).
//
//   mogao_kiosk_image_tool psnr A B      prints the PSNR of A against B in dB ("inf" if identical)
//   mogao_kiosk_image_tool stats A...    prints per file: width height mean (0..255) dark_fraction
//                                        (pixels whose channels are all <= 8)
// A and B are PNG or binary PPM (by extension). Exit codes: 0 done, 1 unreadable or mismatched
// images (the reason on stderr), 2 bad command line.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>

#include "common/image_compare.h"
#include "common/png_io.h"

namespace {

mogao::Rgb8Image read_image(const std::filesystem::path& path) {
    return path.extension() == ".ppm" ? mogao::read_ppm(path) : mogao::read_png(path);
}

int usage() {
    std::fputs("usage: mogao_kiosk_image_tool psnr A B | stats FILE...\n", stderr);
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 3) return usage();
    const std::string command = argv[1];
    try {
        if (command == "psnr") {
            if (argc != 4) return usage();
            const double db = mogao::psnr(read_image(argv[2]), read_image(argv[3]));
            std::printf("%.3f\n", db);
            return 0;
        }
        if (command == "stats") {
            for (int i = 2; i < argc; ++i) {
                const mogao::Rgb8Image image = read_image(argv[i]);
                double sum = 0;
                std::size_t dark = 0;
                const std::size_t pixels = image.pixels.size() / 3;
                for (std::size_t p = 0; p < pixels; ++p) {
                    const auto* px = &image.pixels[p * 3];
                    sum += px[0] + px[1] + px[2];
                    if (px[0] <= 8 && px[1] <= 8 && px[2] <= 8) ++dark;
                }
                std::printf("%s %d %d %.3f %.5f\n", argv[i], image.size.width, image.size.height,
                            pixels ? sum / static_cast<double>(pixels * 3) : 0.0,
                            pixels ? static_cast<double>(dark) / static_cast<double>(pixels) : 1.0);
            }
            return 0;
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mogao_kiosk_image_tool: %s\n", e.what());
        return 1;
    }
    return usage();
}
