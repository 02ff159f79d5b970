// SPDX-License-Identifier: Apache-2.0
// mogao-track make-tag: a printable tag.
#include <cstdio>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "appliance/tools/track_commands.h"
#include "appliance/tracker/tag_bitmap.h"

namespace mogao::track {

int make_tag(const TagImageOptions& o) {
    const TagFamily family(o.family);
    const TagBitmap bitmap = make_tag_bitmap(family, o.id);
    const int cells = bitmap.cells + 2 * o.margin_cells;
    cv::Mat image(cells * o.pixels_per_cell, cells * o.pixels_per_cell, CV_8UC1, cv::Scalar(255));
    for (int y = 0; y < bitmap.cells; ++y) {
        for (int x = 0; x < bitmap.cells; ++x) {
            const cv::Rect cell((x + o.margin_cells) * o.pixels_per_cell, (y + o.margin_cells) * o.pixels_per_cell,
                                o.pixels_per_cell, o.pixels_per_cell);
            image(cell).setTo(bitmap.at(x, y));
        }
    }
    if (!cv::imwrite(o.out.string(), image)) {
        std::fprintf(stderr, "mogao-track make-tag: cannot write %s\n", o.out.string().c_str());
        return 1;
    }
    std::printf("wrote %s: %s id %d; print it so that the black square is the tag size you pass to the tracker\n",
                o.out.string().c_str(), o.family.c_str(), o.id);
    return 0;
}

}  // namespace mogao::track
