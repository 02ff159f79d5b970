// SPDX-License-Identifier: Apache-2.0
// Bytes, encode/decode time and PSNR vs JPEG quality for one frame: the table in docs/encoding.md.
//
//   mogao_jpeg_quality_bench [frame.png|frame.ppm] [--reps N] [--subsampling 420|422|444] [--json FILE]
//
// Without an input it uses a synthetic 1920x1080 "render-like" frame (shaded gradient sky,
// perspective checker floor, shaded discs, mild per-pixel noise like a low-spp path trace). Times
// are medians over N encodes with one reused handle, after a warm-up round; "vs q85" is the encode
// time relative to quality 85 measured in the same run, which survives a noisy shared machine
// better than absolute milliseconds. --json FILE also writes the table as JSON (for
// bench/regenerate-docs, which fills docs/benchmarks.md).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/image_compare.h"
#include "common/jpeg_codec.h"
#include "common/png_io.h"

namespace {

using mogao::ImageSize;
using mogao::Rgb8Image;

std::uint8_t clamp8(double v) { return static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L)); }

Rgb8Image synthetic_frame(ImageSize size) {
    Rgb8Image img(size);
    std::uint32_t rng = 2024;
    const double horizon = 0.45 * size.height;
    for (int y = 0; y < size.height; ++y) {
        for (int x = 0; x < size.width; ++x) {
            double r = 0;
            double g = 0;
            double b = 0;
            if (y < horizon) {  // sky: vertical gradient
                const double t = y / horizon;
                r = 90 + 100 * t;
                g = 140 + 80 * t;
                b = 230 - 20 * t;
            } else {  // floor: checker in perspective, darker with distance
                const double depth = 200.0 / (y - horizon + 1.0);
                const double u = (x - size.width / 2.0) * depth / 40.0;
                const bool dark = (static_cast<long>(std::floor(u)) + static_cast<long>(std::floor(depth))) % 2 != 0;
                const double shade = 1.0 / (1.0 + 0.05 * depth);
                r = (dark ? 70 : 200) * shade;
                g = (dark ? 60 : 180) * shade;
                b = (dark ? 50 : 150) * shade;
            }
            for (int k = 0; k < 5; ++k) {  // five Lambert-shaded spheres seen as discs
                const double cx = size.width * (0.15 + 0.175 * k);
                const double cy = size.height * (0.55 + 0.05 * (k % 2));
                const double rad = size.height * 0.12;
                const double dx = (x - cx) / rad;
                const double dy = (y - cy) / rad;
                if (dx * dx + dy * dy < 1.0) {
                    const double nz = std::sqrt(1.0 - dx * dx - dy * dy);
                    const double lambert = std::max(0.0, -0.5 * dx - 0.5 * dy + 0.7 * nz);
                    r = 40 + 200 * lambert * (k % 3 == 0);
                    g = 40 + 200 * lambert * (k % 3 == 1);
                    b = 40 + 200 * lambert * (k % 3 == 2);
                }
            }
            rng = rng * 1664525u + 1013904223u;
            const double noise = static_cast<int>(rng >> 29) - 3.5;  // +-3.5 levels
            std::uint8_t* p = img.at(x, y);
            p[0] = clamp8(r + noise);
            p[1] = clamp8(g + noise);
            p[2] = clamp8(b + noise);
        }
    }
    return img;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.size() % 2 == 1 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// A JSON string literal (the input path is the only free text written).
std::string json_string(const std::string& s) {
    std::string out = "\"";
    for (const char c : s) {
        if (c == '"' || c == '\\') {
            out += '\\';
            out += c;
        } else if (static_cast<unsigned char>(c) < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(c)));
            out += buf;
        } else {
            out += c;
        }
    }
    return out + "\"";
}

struct Row {
    int quality = 0;
    std::size_t bytes = 0;
    double encode_ms = 0;
    double decode_ms = 0;
    double psnr_db = 0;
};

// Median encode and decode times and the PSNR at each quality; rounds over all qualities rather than all reps of one
// quality: a burst of load from other processes then hits every quality alike and the relative times stay meaningful.
std::vector<Row> measure(const Rgb8Image& image, mogao::Subsampling subsampling, int reps) {
    mogao::JpegEncoder encoder;
    mogao::JpegDecoder decoder;
    using Clock = std::chrono::steady_clock;
    auto ms_since = [](Clock::time_point t0) {
        return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    };
    const std::vector<int> qualities = {50, 60, 70, 75, 80, 85, 90, 95, 100};
    std::vector<std::vector<double>> enc(qualities.size());
    std::vector<std::vector<double>> dec(qualities.size());
    std::vector<std::vector<std::uint8_t>> jpegs(qualities.size());
    std::vector<Rgb8Image> decoded(qualities.size());
    for (int round = -1; round < reps; ++round) {  // round -1 warms caches, clocks and allocations
        for (std::size_t i = 0; i < qualities.size(); ++i) {
            const auto t0 = Clock::now();
            jpegs[i] = encoder.encode(image, qualities[i], subsampling);
            const double e = ms_since(t0);
            const auto t1 = Clock::now();
            decoded[i] = decoder.decode(jpegs[i]);
            const double d = ms_since(t1);
            if (round >= 0) {
                enc[i].push_back(e);
                dec[i].push_back(d);
            }
        }
    }
    std::vector<Row> rows;
    for (std::size_t i = 0; i < qualities.size(); ++i) {
        rows.push_back({qualities[i], jpegs[i].size(), median(enc[i]), median(dec[i]), mogao::psnr(image, decoded[i])});
    }
    return rows;
}

void write_json(const std::string& json_file, const std::string& input, const Rgb8Image& image,
                const std::string& subsampling_name, int reps, const std::vector<Row>& rows) {
    const double pixels = static_cast<double>(image.size.pixel_count());
    const auto q85 = std::find_if(rows.begin(), rows.end(), [](const Row& r) { return r.quality == 85; });
    const double q85_ms = q85->encode_ms;
    std::ofstream out(json_file);
    out << "{\n \"bench\": \"jpeg_quality\",\n \"input\": "
        << json_string(input.empty() ? "synthetic render-like frame" : input) << ",\n \"width\": " << image.size.width
        << ",\n \"height\": " << image.size.height << ",\n \"subsampling\": " << json_string(subsampling_name)
        << ",\n \"reps\": " << reps << ",\n \"rows\": [";
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const Row& r = rows[i];
        char line[320];
        std::snprintf(line, sizeof line,
                      "%s\n  {\"quality\": %d, \"bytes\": %zu, \"bits_per_pixel\": %.6g, \"encode_ms\": %.6g, "
                      "\"encode_vs_q85\": %.6g, \"decode_ms\": %.6g, \"psnr_db\": %.6g}",
                      i == 0 ? "" : ",", r.quality, r.bytes, 8.0 * static_cast<double>(r.bytes) / pixels, r.encode_ms,
                      r.encode_ms / q85_ms, r.decode_ms, r.psnr_db);
        out << line;
    }
    out << "\n ]\n}\n";
    if (!out.flush()) throw std::runtime_error("cannot write " + json_file);
}

int run(int argc, char** argv) {
    std::string input;
    std::string json_file;
    int reps = 15;
    mogao::Subsampling subsampling = mogao::Subsampling::yuv420;
    std::string subsampling_name = "4:2:0";
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--reps" && i + 1 < argc) {
            reps = std::max(1, std::atoi(argv[++i]));
        } else if (arg == "--subsampling" && i + 1 < argc) {
            const std::string s = argv[++i];
            if (s == "444") subsampling = mogao::Subsampling::yuv444;
            else if (s == "422") subsampling = mogao::Subsampling::yuv422;
            else if (s != "420") throw std::invalid_argument("--subsampling takes 420, 422 or 444");
            subsampling_name = s.substr(0, 1) + ":" + s.substr(1, 1) + ":" + s.substr(2, 1);
        } else if (arg == "--json" && i + 1 < argc) {
            json_file = argv[++i];
        } else if (!arg.empty() && arg[0] != '-' && input.empty()) {
            input = arg;
        } else {
            std::fprintf(stderr,
                         "usage: %s [frame.png|frame.ppm] [--reps N] [--subsampling 420|422|444] [--json FILE]\n",
                         argv[0]);
            return 2;
        }
    }

    const std::string ext = std::filesystem::path(input).extension().string();
    const Rgb8Image image = input.empty()                      ? synthetic_frame({1920, 1080})
                            : (ext == ".ppm" || ext == ".pnm") ? mogao::read_ppm(input)
                                                               : mogao::read_png(input);
    std::printf("# input: %s, %dx%d, subsampling %s, median of %d encodes per quality\n",
                input.empty() ? "synthetic render-like frame" : input.c_str(), image.size.width, image.size.height,
                subsampling_name.c_str(), reps);

    const std::vector<Row> rows = measure(image, subsampling, reps);
    const auto q85 = std::find_if(rows.begin(), rows.end(), [](const Row& r) { return r.quality == 85; });
    const double pixels = static_cast<double>(image.size.pixel_count());
    std::printf("| quality | bytes | bits/pixel | encode ms | encode time vs q85 | decode ms | PSNR dB |\n");
    std::printf("|--------:|------:|-----------:|----------:|-------------------:|----------:|--------:|\n");
    for (const Row& r : rows) {
        std::printf("| %d | %zu | %.2f | %.2f | %.2fx | %.2f | %.2f |\n", r.quality, r.bytes,
                    8.0 * static_cast<double>(r.bytes) / pixels, r.encode_ms, r.encode_ms / q85->encode_ms, r.decode_ms,
                    r.psnr_db);
    }
    if (!json_file.empty()) write_json(json_file, input, image, subsampling_name, reps, rows);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mogao_jpeg_quality_bench: %s\n", e.what());
        return 1;
    }
}
