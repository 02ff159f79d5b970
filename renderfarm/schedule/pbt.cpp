// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/schedule/pbt.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

namespace mogao {
namespace {

// Relative tolerance for "same cost": below it, differences are summed-area-table rounding.
constexpr double kRelativeTolerance = 1e-12;

void check_snap(int snap) {
    if (snap < 1) {
        throw std::invalid_argument(fmt::format("PBT snap must be >= 1 pixel (got {})", snap));
    }
}

// First multiple of snap strictly greater than lo (lo >= 0).
int first_snapped_after(int lo, int snap) { return (lo / snap + 1) * snap; }

bool has_interior_snap(int lo, int hi, int snap) { return first_snapped_after(lo, snap) < hi; }

struct Cut {
    SplitAxis axis = SplitAxis::x;
    int position = 0;
    bool area_fallback = false;
};

PixelRect low_part(const PixelRect& r, SplitAxis axis, int p) {
    return axis == SplitAxis::x ? PixelRect{r.x0, r.y0, p, r.y1} : PixelRect{r.x0, r.y0, r.x1, p};
}

PixelRect high_part(const PixelRect& r, SplitAxis axis, int p) {
    return axis == SplitAxis::x ? PixelRect{p, r.y0, r.x1, r.y1} : PixelRect{r.x0, p, r.x1, r.y1};
}

Cut choose_cut(const CostMap& map, const PixelRect& r, int leaves, double cost, double zero_cost, int snap) {
    Cut cut;
    bool along_x = r.width() >= r.height();
    const bool x_ok = has_interior_snap(r.x0, r.x1, snap);
    const bool y_ok = has_interior_snap(r.y0, r.y1, snap);
    if (along_x ? (!x_ok && y_ok) : (!y_ok && x_ok)) {
        along_x = !along_x;  // the longer side cannot be cut inside R, the shorter one can
    }
    cut.axis = along_x ? SplitAxis::x : SplitAxis::y;
    const int lo = along_x ? r.x0 : r.y0;
    const int hi = along_x ? r.x1 : r.y1;
    const int n_low = leaves / 2;
    const int n_high = leaves - n_low;
    cut.area_fallback = cost <= zero_cost;
    const double total = cut.area_fallback ? static_cast<double>(r.area()) : cost;
    const auto low_cost = [&](int p) {
        const PixelRect low = low_part(r, cut.axis, p);
        return cut.area_fallback ? static_cast<double>(low.area()) : map.sum(low);
    };
    const double area_position = lo + static_cast<double>(hi - lo) * n_low / leaves;
    const double tolerance = kRelativeTolerance * total / leaves;

    double best = std::numeric_limits<double>::infinity();
    cut.position = lo;
    const auto consider = [&](int p) {
        const double low = low_cost(p);
        const double per_leaf = std::max(low / n_low, (total - low) / n_high);
        const bool tie = std::abs(per_leaf - best) <= tolerance;
        if ((!tie && per_leaf < best) ||
            (tie && std::abs(p - area_position) < std::abs(cut.position - area_position))) {
            best = std::min(best, per_leaf);
            cut.position = p;
        }
    };
    consider(lo);
    for (int p = first_snapped_after(lo, snap); p < hi; p += snap) {
        consider(p);
    }
    if (hi > lo) {
        consider(hi);
    }
    return cut;
}

}  // namespace

PredictionBinaryTree::PredictionBinaryTree(const CostMap& predicted, int ranks, int snap) : snap_(snap) {
    check_rank_count(ranks);
    check_snap(snap);
    nodes_.reserve(2 * static_cast<std::size_t>(ranks) - 1);
    leaf_of_rank_.assign(static_cast<std::size_t>(ranks), -1);
    const double zero_cost = kRelativeTolerance * predicted.total();
    build(predicted, PixelRect::whole(predicted.size()), ranks, 0, zero_cost);
}

int PredictionBinaryTree::build(const CostMap& map, const PixelRect& rect, int leaves, int first_rank,
                                double zero_cost) {
    const int index = static_cast<int>(nodes_.size());
    PbtNode node;
    node.rect = rect;
    node.leaves = leaves;
    node.first_rank = first_rank;
    node.predicted_cost = map.sum(rect);
    nodes_.push_back(node);
    if (leaves == 1) {
        leaf_of_rank_[static_cast<std::size_t>(first_rank)] = index;
        return index;
    }
    const Cut cut = choose_cut(map, rect, leaves, node.predicted_cost, zero_cost, snap_);
    const int n_low = leaves / 2;
    const int low = build(map, low_part(rect, cut.axis, cut.position), n_low, first_rank, zero_cost);
    const int high = build(map, high_part(rect, cut.axis, cut.position), leaves - n_low, first_rank + n_low, zero_cost);
    PbtNode& stored = nodes_[static_cast<std::size_t>(index)];  // re-fetched: recursion grew the vector
    stored.axis = cut.axis;
    stored.split = cut.position;
    stored.area_fallback = cut.area_fallback;
    stored.children = {low, high};
    return index;
}

const PbtNode& PredictionBinaryTree::leaf(int rank) const {
    if (rank < 0 || rank >= ranks()) {
        throw std::invalid_argument(fmt::format("PBT rank must be in [0,{}) (got {})", ranks(), rank));
    }
    return nodes_[static_cast<std::size_t>(leaf_of_rank_[static_cast<std::size_t>(rank)])];
}

std::vector<PixelRect> PredictionBinaryTree::leaf_rects() const {
    std::vector<PixelRect> rects;
    rects.reserve(leaf_of_rank_.size());
    for (const int index : leaf_of_rank_) {
        rects.push_back(nodes_[static_cast<std::size_t>(index)].rect);
    }
    return rects;
}

namespace {

Assignment assignment_from_tree(const PredictionBinaryTree& tree, const CostMap& predicted) {
    Assignment out;
    for (const PixelRect& rect : tree.leaf_rects()) {
        out.rects.push_back({rect});
        out.predicted_cost.push_back(predicted.sum(rect));
    }
    return out;
}

}  // namespace

PbtBalancer::PbtBalancer(int snap) : snap_(snap) { check_snap(snap); }

Assignment PbtBalancer::assign(const CostMap& predicted, int ranks) const {
    return assignment_from_tree(PredictionBinaryTree(predicted, ranks, snap_), predicted);
}

EqualSplitBalancer::EqualSplitBalancer(int snap) : snap_(snap) { check_snap(snap); }

Assignment EqualSplitBalancer::assign(const CostMap& predicted, int ranks) const {
    const CostMap area = CostMap::uniform(predicted.size(), predicted.cell_size());
    return assignment_from_tree(PredictionBinaryTree(area, ranks, snap_), predicted);
}

}  // namespace mogao
