// SPDX-License-Identifier: Apache-2.0
// Cost map of the schedule stage: predicted render time of each cell of a frame.
//
// Shape: the image (ImageSize, pixels) is covered by a grid of cells_x() x cells_y() square cells of
// cell_size() pixels; cell (cx, cy) covers the pixel rect
//   [cx*cell_size, min((cx+1)*cell_size, width)) x [cy*cell_size, min((cy+1)*cell_size, height)),
// so the last column and row of cells may be partial (pixel convention of common/pixel_rect.h).
// Units: each cell holds the predicted time in seconds to render all of its pixels (>= 0, finite).
//
// Sum queries are O(1) through a summed-area table (Crow 1984, "Summed-area tables for texture
// mapping"). The table is rebuilt lazily by the first sum()/total() after a set_cell(), or
// explicitly by finalize(). Because of that lazy rebuild, concurrent const calls on the same map are
// only safe after finalize() (or any sum) has run since the last mutation.
//
// Errors: every bad argument throws std::invalid_argument whose message names the field and limit.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "common/pixel_rect.h"

namespace mogao {

// Measured time of one tile rendered by a rank (what the farm logs per frame, see tile-costs.json in
// docs/load-balancing.md). The rect is normally cell-aligned, but need not be.
struct TileTime {
    PixelRect rect;        // pixels, inside the image, non-empty when seconds > 0
    double seconds = 0.0;  // wall time of the tile, >= 0 and finite
};

class CostMap {
public:
    static constexpr int kDefaultCellSize = 16;  // pixels; matches the PBT snap and JPEG 16x16 MCUs

    // All cells cost 0. image: width, height >= 0 (a 0-sized image has no cells); cell_size >= 1.
    explicit CostMap(ImageSize image, int cell_size = kDefaultCellSize);

    // Cost proportional to pixel count: each cell costs seconds_per_pixel * (its pixel count). This
    // is the prediction of the first frame, before any tile has been timed.
    [[nodiscard]] static CostMap uniform(ImageSize image, int cell_size = kDefaultCellSize,
                                         double seconds_per_pixel = 1.0);

    // Spreads each tile's seconds over the cells it overlaps, pro rata to the overlapped pixel count,
    // so the map's total equals the sum of the tile times (up to rounding). Overlapping tiles add up.
    // Throws if a time is negative/NaN/inf, a non-empty tile leaves the image, or a tile with
    // seconds > 0 is empty (its time could not be placed).
    [[nodiscard]] static CostMap from_tile_times(ImageSize image, int cell_size, std::span<const TileTime> tiles);

    // The same predicted costs for the same view rendered at another size (a live session's
    // resolution scale changes from frame to frame, frame_time_controller.h): each cell of the new
    // map takes sum() over the corresponding rect of this map (edges scaled by the size ratio and
    // rounded to pixels), so relative costs carry over and the total stays close to this map's.
    // image: width, height >= 0; cell_size >= 1 (else throws like the constructor).
    [[nodiscard]] CostMap resampled(ImageSize image, int cell_size) const;

    [[nodiscard]] ImageSize size() const { return size_; }
    [[nodiscard]] int cell_size() const { return cell_size_; }
    [[nodiscard]] int cells_x() const { return cells_x_; }
    [[nodiscard]] int cells_y() const { return cells_y_; }
    // Pixel rect of cell (cx, cy), clipped to the image. Throws if the cell index is out of range.
    [[nodiscard]] PixelRect cell_rect(int cx, int cy) const;

    // Predicted seconds of cell (cx, cy); 0 <= cx < cells_x(), 0 <= cy < cells_y(), else throws.
    [[nodiscard]] double cell(int cx, int cy) const;
    // Sets cell (cx, cy) to `seconds` (finite, >= 0). Invalidates the summed-area table.
    void set_cell(int cx, int cy, double seconds);

    // Builds the summed-area table now (otherwise the next sum()/total() does it).
    void finalize() const;

    // Predicted seconds of a pixel rect. Empty rects cost 0 wherever they are; a non-empty rect must
    // lie inside the image, else throws. Cell-aligned rects (edges on multiples of cell_size or on
    // the image border) are exact sums of whole cells. For other rects each partially covered cell
    // contributes pro rata to the covered pixel area (the cost density is taken as constant inside
    // a cell), still in O(1): the integral of a piecewise-constant density is bilinear inside a
    // cell, so the table is interpolated between the cell's corners.
    [[nodiscard]] double sum(const PixelRect& rect) const;
    // Predicted seconds of the whole image.
    [[nodiscard]] double total() const;

private:
    [[nodiscard]] std::size_t cell_index(int cx, int cy) const;
    void check_cell(int cx, int cy) const;
    // Cost of [0, x) x [0, y) for 0 <= x <= width, 0 <= y <= height.
    [[nodiscard]] double prefix(int x, int y) const;

    ImageSize size_;
    int cell_size_;
    int cells_x_;
    int cells_y_;
    std::vector<double> cells_;  // row-major, cells_x_ * cells_y_
    // (cells_x_+1) x (cells_y_+1) table: sat_[j*(cells_x_+1)+i] = cost of cells [0,i) x [0,j).
    mutable std::vector<double> sat_;
    mutable bool sat_valid_ = false;
};

}  // namespace mogao
