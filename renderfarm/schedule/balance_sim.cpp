// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/schedule/balance_sim.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include "renderfarm/schedule/balance_efficiency.h"
#include "renderfarm/schedule/load_balancer.h"

namespace mogao {

std::vector<BalanceSimResult> simulate_balance(std::span<const CostMap> frames, const BalanceSimOptions& options) {
    if (frames.empty()) {
        throw std::invalid_argument("simulate_balance: frames must hold at least 1 cost map (got 0)");
    }
    for (std::size_t f = 1; f < frames.size(); ++f) {
        if (frames[f].size() != frames[0].size() || frames[f].cell_size() != frames[0].cell_size()) {
            throw std::invalid_argument(fmt::format(
                "simulate_balance: frames[{}] is {}x{} cell {} but frames[0] is {}x{} cell {}; all must match", f,
                frames[f].size().width, frames[f].size().height, frames[f].cell_size(), frames[0].size().width,
                frames[0].size().height, frames[0].cell_size()));
        }
    }
    std::vector<std::unique_ptr<LoadBalancer>> balancers;
    for (const std::string& name : options.balancers) {
        balancers.push_back(make_load_balancer(name, name == "roundrobin" ? options.tile : options.snap));
    }
    for (const int ranks : options.rank_counts) {
        check_rank_count(ranks);
    }
    const CostMap first = CostMap::uniform(frames[0].size(), frames[0].cell_size());
    std::vector<BalanceSimResult> results;
    for (const int ranks : options.rank_counts) {
        for (const auto& balancer : balancers) {
            BalanceSimResult r;
            r.balancer = std::string(balancer->name());
            r.ranks = ranks;
            std::size_t rects = 0;
            for (std::size_t f = 0; f < frames.size(); ++f) {
                const CostMap& predicted = f == 0 ? first : frames[f - 1];
                const Assignment assignment = balancer->assign(predicted, ranks);
                r.efficiency.push_back(balance_efficiency(assignment, frames[f]));
                for (const auto& list : assignment.rects) {
                    rects += static_cast<std::size_t>(
                        std::count_if(list.begin(), list.end(), [](const PixelRect& p) { return !p.empty(); }));
                }
            }
            r.mean_rects_per_rank =
                static_cast<double>(rects) / static_cast<double>(frames.size()) / static_cast<double>(ranks);
            double sum = 0.0;
            for (const double e : r.efficiency) {
                sum += e;
            }
            r.mean_efficiency = sum / static_cast<double>(r.efficiency.size());
            r.min_efficiency = *std::min_element(r.efficiency.begin(), r.efficiency.end());
            results.push_back(std::move(r));
        }
    }
    return results;
}

namespace {

std::optional<double> mean_of(std::span<const BalanceSimResult> results, int ranks, std::string_view name) {
    for (const auto& r : results) {
        if (r.ranks == ranks && r.balancer == name) {
            return r.mean_efficiency;
        }
    }
    return std::nullopt;
}

std::string ratio_text(std::optional<double> num, std::optional<double> den) {
    if (!num || !den || *den <= 0.0) {
        return "n/a";
    }
    return fmt::format("{:.3f}", *num / *den);
}

}  // namespace

std::string balance_table_markdown(std::span<const BalanceSimResult> results) {
    std::string out =
        "| ranks | balancer | frames | mean efficiency | min efficiency | rects per rank |\n"
        "|------:|----------|-------:|----------------:|---------------:|---------------:|\n";
    std::vector<int> rank_counts;
    for (const auto& r : results) {
        out += fmt::format("| {} | {} | {} | {:.3f} | {:.3f} | {:.1f} |\n", r.ranks, r.balancer, r.efficiency.size(),
                           r.mean_efficiency, r.min_efficiency, r.mean_rects_per_rank);
        if (std::find(rank_counts.begin(), rank_counts.end(), r.ranks) == rank_counts.end()) {
            rank_counts.push_back(r.ranks);
        }
    }
    out +=
        "\n| ranks | pbt/equal (mean) | pbt/roundrobin (mean) |\n"
        "|------:|-----------------:|----------------------:|\n";
    for (const int n : rank_counts) {
        const auto pbt = mean_of(results, n, "pbt");
        out += fmt::format("| {} | {} | {} |\n", n, ratio_text(pbt, mean_of(results, n, "equal")),
                           ratio_text(pbt, mean_of(results, n, "roundrobin")));
    }
    return out;
}

std::vector<CostMap> moving_hotspot_frames(const MovingHotspot& spec) {
    if (spec.frames < 0) {
        throw std::invalid_argument(fmt::format("MovingHotspot.frames must be >= 0 (got {})", spec.frames));
    }
    if (!(spec.sigma_px > 0.0) || !std::isfinite(spec.sigma_px)) {
        throw std::invalid_argument(
            fmt::format("MovingHotspot.sigma_px must be finite and > 0 (got {})", spec.sigma_px));
    }
    if (!(spec.peak_ratio >= 0.0) || !std::isfinite(spec.peak_ratio) || !std::isfinite(spec.speed_px_per_frame)) {
        throw std::invalid_argument("MovingHotspot.peak_ratio must be finite and >= 0, speed_px_per_frame finite");
    }
    const double cx = spec.image.width / 2.0;
    const double cy = spec.image.height / 2.0;
    const double radius = 0.3 * std::min(spec.image.width, spec.image.height);
    const double step = radius > 0.0 ? spec.speed_px_per_frame / radius : 0.0;  // radians per frame
    std::vector<CostMap> frames;
    for (int f = 0; f < spec.frames; ++f) {
        CostMap map(spec.image, spec.cell_size);
        const double angle = step * f;
        const double hx = cx + radius * std::cos(angle);
        const double hy = cy + radius * std::sin(angle);
        for (int j = 0; j < map.cells_y(); ++j) {
            for (int i = 0; i < map.cells_x(); ++i) {
                const PixelRect r = map.cell_rect(i, j);
                const double dx = (r.x0 + r.x1) / 2.0 - hx;
                const double dy = (r.y0 + r.y1) / 2.0 - hy;
                const double hot =
                    spec.peak_ratio * std::exp(-(dx * dx + dy * dy) / (2.0 * spec.sigma_px * spec.sigma_px));
                map.set_cell(i, j, spec.background_seconds_per_pixel * (1.0 + hot) * static_cast<double>(r.area()));
            }
        }
        frames.push_back(std::move(map));
    }
    return frames;
}

}  // namespace mogao
