// SPDX-License-Identifier: Apache-2.0
// mogao-track detect: every tag's id and corners per image.
#include <cstdio>

#include <nlohmann/json.hpp>

#include "appliance/tools/track_commands.h"
#include "appliance/tracker/tag_detector.h"
#include "drivers/camera/image_file.h"

namespace mogao::track {

int detect(const DetectOptions& options) {
    TagDetector detector(options.detector);
    nlohmann::json all = nlohmann::json::array();
    int failed = 0;
    for (const auto& path : options.images) {
        auto image = read_gray_image(path);
        if (!image) {
            std::fprintf(stderr, "mogao-track detect: %s\n", image.error().message.c_str());
            ++failed;
            continue;
        }
        const auto detections = detector.detect(*image);
        if (options.json) {
            nlohmann::json entry{{"image", path.string()},
                                 {"width", image->width},
                                 {"height", image->height},
                                 {"family", detector.family().name()},
                                 {"detections", nlohmann::json::array()}};
            for (const auto& det : detections) {
                nlohmann::json corners = nlohmann::json::array();
                for (const auto& p : det.corners) corners.push_back({p.x(), p.y()});
                entry["detections"].push_back({{"id", det.id},
                                               {"hamming", det.hamming},
                                               {"decision_margin", det.decision_margin},
                                               {"corners", corners},
                                               {"centre", {det.centre.x(), det.centre.y()}}});
            }
            all.push_back(entry);
            continue;
        }
        std::printf("%s: %dx%d, %zu %s detection(s)\n", path.string().c_str(), image->width, image->height,
                    detections.size(), detector.family().name().c_str());
        for (const auto& det : detections) {
            std::printf("  id %d  hamming %d  margin %.1f  corners", det.id, det.hamming,
                        static_cast<double>(det.decision_margin));
            for (const auto& p : det.corners) std::printf("  (%.3f, %.3f)", p.x(), p.y());
            std::printf("\n");
        }
    }
    if (options.json) {  // one image per line: a valid JSON array that still reads well in a terminal
        std::printf("[\n");
        for (std::size_t i = 0; i < all.size(); ++i)
            std::printf("%s%s\n", all[i].dump().c_str(), i + 1 < all.size() ? "," : "");
        std::printf("]\n");
    }
    return failed == 0 ? 0 : 1;
}

}  // namespace mogao::track
