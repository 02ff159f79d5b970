// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/schedule/cost_map.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

namespace mogao {
namespace {

int cell_count(int pixels, int cell_size) { return (pixels + cell_size - 1) / cell_size; }

void check_seconds(double seconds, const char* field) {
    if (!std::isfinite(seconds) || seconds < 0.0) {
        throw std::invalid_argument(fmt::format("{} must be finite and >= 0 seconds (got {})", field, seconds));
    }
}

bool inside(const PixelRect& r, ImageSize s) { return r.x0 >= 0 && r.y0 >= 0 && r.x1 <= s.width && r.y1 <= s.height; }

std::string rect_text(const PixelRect& r) { return fmt::format("[{},{})x[{},{})", r.x0, r.x1, r.y0, r.y1); }

}  // namespace

CostMap::CostMap(ImageSize image, int cell_size) : size_(image), cell_size_(cell_size) {
    if (cell_size < 1) {
        throw std::invalid_argument(fmt::format("CostMap cell_size must be >= 1 pixel (got {})", cell_size));
    }
    if (image.width < 0 || image.height < 0) {
        throw std::invalid_argument(
            fmt::format("CostMap image width and height must be >= 0 (got {}x{})", image.width, image.height));
    }
    cells_x_ = cell_count(image.width, cell_size);
    cells_y_ = cell_count(image.height, cell_size);
    cells_.assign(static_cast<std::size_t>(cells_x_) * static_cast<std::size_t>(cells_y_), 0.0);
}

CostMap CostMap::uniform(ImageSize image, int cell_size, double seconds_per_pixel) {
    check_seconds(seconds_per_pixel, "CostMap::uniform seconds_per_pixel");
    CostMap map(image, cell_size);
    for (int cy = 0; cy < map.cells_y_; ++cy) {
        for (int cx = 0; cx < map.cells_x_; ++cx) {
            map.cells_[map.cell_index(cx, cy)] = seconds_per_pixel * static_cast<double>(map.cell_rect(cx, cy).area());
        }
    }
    return map;
}

CostMap CostMap::resampled(ImageSize image, int cell_size) const {
    CostMap map(image, cell_size);
    if (size_.pixel_count() == 0) return map;
    const auto to_old = [](int v, int from, int to) {
        return static_cast<int>(std::lround(static_cast<double>(v) * to / std::max(1, from)));
    };
    for (int cy = 0; cy < map.cells_y_; ++cy) {
        for (int cx = 0; cx < map.cells_x_; ++cx) {
            const PixelRect r = map.cell_rect(cx, cy);
            PixelRect old{to_old(r.x0, image.width, size_.width), to_old(r.y0, image.height, size_.height),
                          to_old(r.x1, image.width, size_.width), to_old(r.y1, image.height, size_.height)};
            old.x1 = std::min(size_.width, std::max(old.x1, old.x0 + 1));
            old.y1 = std::min(size_.height, std::max(old.y1, old.y0 + 1));
            old.x0 = std::min(old.x0, old.x1 - 1);
            old.y0 = std::min(old.y0, old.y1 - 1);
            map.cells_[map.cell_index(cx, cy)] = sum(old);
        }
    }
    return map;
}

CostMap CostMap::from_tile_times(ImageSize image, int cell_size, std::span<const TileTime> tiles) {
    CostMap map(image, cell_size);
    for (std::size_t t = 0; t < tiles.size(); ++t) {
        const TileTime& tile = tiles[t];
        check_seconds(tile.seconds, "TileTime.seconds");
        if (tile.rect.empty()) {
            if (tile.seconds > 0.0) {
                throw std::invalid_argument(
                    fmt::format("TileTime.rect of tile {} is empty {} but has {} s: its time cannot be placed", t,
                                rect_text(tile.rect), tile.seconds));
            }
            continue;
        }
        if (!inside(tile.rect, image)) {
            throw std::invalid_argument(fmt::format("TileTime.rect of tile {} is {}, outside the image [0,{})x[0,{})",
                                                    t, rect_text(tile.rect), image.width, image.height));
        }
        const double per_pixel = tile.seconds / static_cast<double>(tile.rect.area());
        for (int cy = tile.rect.y0 / cell_size; cy <= (tile.rect.y1 - 1) / cell_size; ++cy) {
            for (int cx = tile.rect.x0 / cell_size; cx <= (tile.rect.x1 - 1) / cell_size; ++cx) {
                const auto overlap = intersect(tile.rect, map.cell_rect(cx, cy)).area();
                map.cells_[map.cell_index(cx, cy)] += per_pixel * static_cast<double>(overlap);
            }
        }
    }
    return map;
}

std::size_t CostMap::cell_index(int cx, int cy) const {
    return static_cast<std::size_t>(cy) * static_cast<std::size_t>(cells_x_) + static_cast<std::size_t>(cx);
}

void CostMap::check_cell(int cx, int cy) const {
    if (cx < 0 || cx >= cells_x_ || cy < 0 || cy >= cells_y_) {
        throw std::invalid_argument(
            fmt::format("CostMap cell ({}, {}) is outside the grid: cx must be in [0,{}), cy in [0,{})", cx, cy,
                        cells_x_, cells_y_));
    }
}

PixelRect CostMap::cell_rect(int cx, int cy) const {
    check_cell(cx, cy);
    return {cx * cell_size_, cy * cell_size_, std::min((cx + 1) * cell_size_, size_.width),
            std::min((cy + 1) * cell_size_, size_.height)};
}

double CostMap::cell(int cx, int cy) const {
    check_cell(cx, cy);
    return cells_[cell_index(cx, cy)];
}

void CostMap::set_cell(int cx, int cy, double seconds) {
    check_cell(cx, cy);
    check_seconds(seconds, "CostMap cell seconds");
    cells_[cell_index(cx, cy)] = seconds;
    sat_valid_ = false;
}

void CostMap::finalize() const {
    if (sat_valid_) {
        return;
    }
    const auto stride = static_cast<std::size_t>(cells_x_) + 1;
    sat_.assign(stride * (static_cast<std::size_t>(cells_y_) + 1), 0.0);
    for (int cy = 0; cy < cells_y_; ++cy) {
        double row = 0.0;  // running sum of this cell row, so each entry adds one rounding step
        const auto j = static_cast<std::size_t>(cy);
        for (int cx = 0; cx < cells_x_; ++cx) {
            row += cells_[cell_index(cx, cy)];
            const auto i = static_cast<std::size_t>(cx) + 1;
            sat_[(j + 1) * stride + i] = sat_[j * stride + i] + row;
        }
    }
    sat_valid_ = true;
}

double CostMap::prefix(int x, int y) const {
    // Cell column i0 holding x, and the fraction of that column's width left of x (0 on boundaries,
    // so cell-aligned queries read the table exactly).
    const auto locate = [this](int p, int extent, int cells, int& index) {
        if (p >= extent) {
            index = cells;
            return 0.0;
        }
        index = p / cell_size_;
        const int start = index * cell_size_;
        const int width = std::min(start + cell_size_, extent) - start;
        return static_cast<double>(p - start) / static_cast<double>(width);
    };
    int i0 = 0;
    int j0 = 0;
    const double fx = locate(x, size_.width, cells_x_, i0);
    const double fy = locate(y, size_.height, cells_y_, j0);
    const auto stride = static_cast<std::size_t>(cells_x_) + 1;
    const auto at = [&](int i, int j) {
        return sat_[static_cast<std::size_t>(j) * stride + static_cast<std::size_t>(i)];
    };
    double value = at(i0, j0);
    if (fx > 0.0) {
        value += fx * (at(i0 + 1, j0) - at(i0, j0));
    }
    if (fy > 0.0) {
        value += fy * (at(i0, j0 + 1) - at(i0, j0));
        if (fx > 0.0) {
            value += fx * fy * (at(i0 + 1, j0 + 1) - at(i0, j0 + 1) - at(i0 + 1, j0) + at(i0, j0));
        }
    }
    return value;
}

double CostMap::sum(const PixelRect& rect) const {
    if (rect.empty()) {
        return 0.0;
    }
    if (!inside(rect, size_)) {
        throw std::invalid_argument(fmt::format("CostMap::sum rect {} is outside the image [0,{})x[0,{})",
                                                rect_text(rect), size_.width, size_.height));
    }
    finalize();
    const double s =
        prefix(rect.x1, rect.y1) - prefix(rect.x0, rect.y1) - prefix(rect.x1, rect.y0) + prefix(rect.x0, rect.y0);
    // Costs are >= 0; a tiny negative value is rounding in the table differences.
    return std::max(0.0, s);
}

double CostMap::total() const { return sum(PixelRect::whole(size_)); }

}  // namespace mogao
