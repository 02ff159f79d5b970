// SPDX-License-Identifier: Apache-2.0
// Prediction binary tree (PBT): the sort-first split of a frame over the render ranks.
//
// Source: the seed paper, "Immersive Virtual Tour using Multi-projection with Remote Cluster
// Rendering", re-balances a prediction binary tree every frame from the tile times measured in the
// previous frame; the kd split itself follows sort-first balancing as in Samanta et al., "Load
// balancing for multi-projector rendering systems" (Graphics Hardware 1999) and "Hybrid sort-first
// and sort-last parallel rendering with a cluster of PCs" (Graphics Hardware 2000).
// Full description, degenerate cases and bounds: docs/load-balancing.md.
//
// Tree shape: the root covers the whole image with `ranks` leaves; a node with n >= 2 leaves is cut
// into a low child with floor(n/2) leaves and a high child with ceil(n/2) leaves. Leaves are the
// ranks, numbered left to right (depth first): rank r is the r-th leaf. Every pixel is in exactly
// one leaf; leaves may be empty rects (more ranks than snapped positions, empty images).
//
// Cut rule at a node of rect R, cost C (seconds, CostMap::sum(R)), n leaves:
//  * axis: the longer side of R (width >= height -> cut across x), unless that side has no snapped
//    position strictly inside R and the other side has one;
//  * candidate positions p: the multiples of `snap` in absolute image pixels strictly inside R,
//    plus R's own two edges (a cut there leaves one child empty). So every cut lies on a multiple
//    of snap, except a cut on R's edge, which is itself a snapped cut or the image border;
//  * the chosen p minimises the predicted cost per leaf of the worse child,
//    max(L(p) / floor(n/2), (C - L(p)) / ceil(n/2)), L(p) = cost of the low child [lo, p),
//    ties (within 1e-12 relative) going to the p closest to the area-proportional position;
//  * zero-cost node (C <= 1e-12 of the frame's total, e.g. all-zero map, or the cold side of a hot
//    pixel): the same rule with pixel area as cost, so idle regions are still split evenly.
// A leaf can be an empty rect: when R has fewer snapped positions than leaves, or when the cost
// minimum is a cut on R's edge (e.g. R's cost is one hot pixel in its first snap column and R has 3
// leaves: giving the low leaf nothing and the hot pixel to the 2-leaf side is the predicted optimum).
// Bound (tested): with p_a the last candidate with L <= C*floor(n/2)/n and p_b the next one, the
// low child's cost differs from its ideal C*floor(n/2)/n by at most the cost of the strip
// [p_a, p_b) across R; each leaf differs from total/ranks by at most the sum of those strip costs
// over its ancestors.
#pragma once

#include <array>
#include <string_view>
#include <vector>

#include "common/pixel_rect.h"
#include "renderfarm/schedule/cost_map.h"
#include "renderfarm/schedule/load_balancer.h"

namespace mogao {

enum class SplitAxis {
    none,  // leaf
    x,     // vertical cut at x = split: low child [x0, split), high child [split, x1)
    y,     // horizontal cut at y = split: low child [y0, split), high child [split, y1)
};

struct PbtNode {
    PixelRect rect;      // pixels covered by this node
    int leaves = 1;      // ranks under this node
    int first_rank = 0;  // its leaves are ranks first_rank .. first_rank + leaves - 1
    SplitAxis axis = SplitAxis::none;
    int split = 0;                        // absolute pixel coordinate of the cut; 0 for leaves
    double predicted_cost = 0.0;          // seconds, CostMap::sum(rect) of the map the tree was built from
    bool area_fallback = false;           // cut by pixel area because the node predicted zero cost
    std::array<int, 2> children{-1, -1};  // indices into nodes(): low side, high side; -1 for leaves
};

class PredictionBinaryTree {
public:
    static constexpr int kDefaultSnap = 16;  // pixels; 16x16 JPEG MCUs with 4:2:0 chroma, one cost cell

    // ranks in [1, LoadBalancer::kMaxRanks], snap >= 1 (8 or 16 in the farm); else std::invalid_argument.
    PredictionBinaryTree(const CostMap& predicted, int ranks, int snap = kDefaultSnap);

    [[nodiscard]] const std::vector<PbtNode>& nodes() const { return nodes_; }  // [0] is the root, pre-order
    [[nodiscard]] int ranks() const { return static_cast<int>(leaf_of_rank_.size()); }
    [[nodiscard]] int snap() const { return snap_; }
    [[nodiscard]] const PbtNode& leaf(int rank) const;        // throws std::invalid_argument if rank is out of range
    [[nodiscard]] std::vector<PixelRect> leaf_rects() const;  // index = rank

private:
    int build(const CostMap& map, const PixelRect& rect, int leaves, int first_rank, double zero_cost);

    int snap_;
    std::vector<PbtNode> nodes_;
    std::vector<int> leaf_of_rank_;  // node index of each rank's leaf
};

// "pbt": the PBT built on the predicted map (the previous frame's measured costs; uniform for frame 0).
class PbtBalancer final : public LoadBalancer {
public:
    explicit PbtBalancer(int snap = PredictionBinaryTree::kDefaultSnap);  // snap >= 1
    [[nodiscard]] Assignment assign(const CostMap& predicted, int ranks) const override;
    [[nodiscard]] std::string_view name() const override { return "pbt"; }

private:
    int snap_;
};

// "equal": the same kd split on pixel area (static equal-area split), ignoring the predicted costs;
// predicted_cost in its Assignment still comes from the given map.
class EqualSplitBalancer final : public LoadBalancer {
public:
    explicit EqualSplitBalancer(int snap = PredictionBinaryTree::kDefaultSnap);  // snap >= 1
    [[nodiscard]] Assignment assign(const CostMap& predicted, int ranks) const override;
    [[nodiscard]] std::string_view name() const override { return "equal"; }

private:
    int snap_;
};

}  // namespace mogao
