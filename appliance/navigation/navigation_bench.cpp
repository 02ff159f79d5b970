// SPDX-License-Identifier: Apache-2.0
// One Euro filter vs a plain first-order low-pass on the tag's yaw (docs/tracking.md, "Jitter
// filter"). Not a test: prints a table and ratios measured in the same run.
//
// Signal: the yaw a tracker reports at 30 Hz, truth + Gaussian noise (sigma as measured on the
// hand-held sequence by `mogao-track navigate`), 4 s at rest then a fast turn of 30 deg in
// 0.4 s (smoothstep), then 2 s held. Metrics:
//   jitter  standard deviation of the output over the last 3 s of rest (deg)
//   lag     mean delay of the output behind the truth during the turn: the time shift that best
//           aligns them (least squares over the turn and 0.3 s after), in ms
//   rms     RMS error against the truth during the turn (deg)
// Filters: the One Euro filter with mogao's angle parameters (navigator.h, or the ones given);
// and two plain low-passes whose cutoffs are searched so that one has One Euro's jitter at rest
// and the other One Euro's lag on the turn.
//
// Usage: mogao_navigation_bench [noise_sigma_deg [min_cutoff_hz beta]]
//   noise default 1.0 deg: the tracker's yaw noise on a near-frontal tag at 0.5 m (the worst
//   case, `mogao-track navigate` on the hand-held sequence; docs/tracking.md).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <random>
#include <vector>

#include "appliance/navigation/low_pass_filter.h"
#include "appliance/navigation/navigator.h"
#include "appliance/navigation/one_euro_filter.h"

namespace {

constexpr double kRate = 30.0;
constexpr double kRestEnd = 4.0;
constexpr double kTurnEnd = 4.4;
constexpr double kEnd = 6.4;
constexpr double kTurnDeg = 30.0;

double truth(double t) {
    const double x = std::clamp((t - kRestEnd) / (kTurnEnd - kRestEnd), 0.0, 1.0);
    return kTurnDeg * x * x * (3.0 - 2.0 * x);
}

struct Metrics {
    double jitter_deg;
    double lag_ms;
    double rms_deg;
};

Metrics measure(const std::function<double(double, double)>& filter, double sigma, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, sigma);
    std::vector<double> ts;
    std::vector<double> ys;
    for (int i = 0; i <= static_cast<int>(kEnd * kRate); ++i) {
        const double t = i / kRate;
        ts.push_back(t);
        ys.push_back(filter(truth(t) + noise(rng), t));
    }
    double mean = 0.0;
    double sq = 0.0;
    int n = 0;
    for (std::size_t i = 0; i < ts.size(); ++i) {
        if (ts[i] >= 1.0 && ts[i] < kRestEnd) mean += ys[i], sq += ys[i] * ys[i], ++n;
    }
    mean /= n;
    Metrics m{};
    m.jitter_deg = std::sqrt(std::max(0.0, sq / n - mean * mean));
    // Lag: the shift d (0..500 ms, 1 ms steps) minimising sum (y(t) - truth(t - d))^2 over the turn.
    double best = 1e300;
    for (int d = 0; d <= 500; ++d) {
        double e = 0.0;
        for (std::size_t i = 0; i < ts.size(); ++i) {
            if (ts[i] >= kRestEnd && ts[i] <= kTurnEnd + 0.3) e += std::pow(ys[i] - truth(ts[i] - d * 1e-3), 2);
        }
        if (e < best) best = e, m.lag_ms = d;
    }
    double se = 0.0;
    int k = 0;
    for (std::size_t i = 0; i < ts.size(); ++i) {
        if (ts[i] >= kRestEnd && ts[i] <= kTurnEnd + 0.3) se += std::pow(ys[i] - truth(ts[i]), 2), ++k;
    }
    m.rms_deg = std::sqrt(se / k);
    return m;
}

// Averages over several noise seeds so the figures do not hinge on one draw.
Metrics average(const std::function<std::function<double(double, double)>()>& make, double sigma) {
    Metrics sum{};
    constexpr int kRuns = 20;
    for (int s = 0; s < kRuns; ++s) {
        const Metrics m = measure(make(), sigma, 1000U + static_cast<unsigned>(s));
        sum.jitter_deg += m.jitter_deg / kRuns;
        sum.lag_ms += m.lag_ms / kRuns;
        sum.rms_deg += m.rms_deg / kRuns;
    }
    return sum;
}

std::function<std::function<double(double, double)>()> low_pass(double cutoff) {
    return [cutoff] {
        auto f = std::make_shared<mogao::LowPassFilter>(cutoff);
        return [f](double x, double t) { return f->filter(x, t); };
    };
}

}  // namespace

int main(int argc, char** argv) {
    const double sigma = argc > 1 ? std::atof(argv[1]) : 1.0;
    mogao::OneEuroParams params = mogao::NavigationParams{}.angle_filter;
    if (argc > 3) {
        params.min_cutoff_hz = std::atof(argv[2]);
        params.beta = std::atof(argv[3]);
    }
    if (!(sigma >= 0.0 && sigma < 100.0)) {
        std::fprintf(stderr, "noise sigma %s outside [0, 100) deg\n", argv[1]);
        return 2;
    }
    const auto one_euro = [params] {
        auto f = std::make_shared<mogao::OneEuroFilter>(params);
        return [f](double x, double t) { return f->filter(x, t); };
    };
    const auto identity = [] { return [](double x, double) { return x; }; };

    const Metrics raw = average(identity, sigma);
    const Metrics oe = average(one_euro, sigma);
    // Low-pass cutoffs matching One Euro's jitter and its lag. Jitter rises and lag falls with the
    // cutoff; bisect in log space.
    const auto match = [&](const std::function<bool(const Metrics&)>& cutoff_too_low) {
        double lo = 0.05;
        double hi = 30.0;
        for (int i = 0; i < 30; ++i) {
            const double mid = std::sqrt(lo * hi);
            (cutoff_too_low(average(low_pass(mid), sigma)) ? lo : hi) = mid;
        }
        return std::sqrt(lo * hi);
    };
    const double jitter_cutoff = match([&](const Metrics& m) { return m.jitter_deg < oe.jitter_deg; });
    const double lag_cutoff = match([&](const Metrics& m) { return m.lag_ms > oe.lag_ms; });
    const Metrics lp_jitter = average(low_pass(jitter_cutoff), sigma);
    const Metrics lp_lag = average(low_pass(lag_cutoff), sigma);

    std::printf("yaw at 30 Hz, noise sigma %.2f deg; rest 4 s, then %.0f deg in %.1f s (mean of 20 noise draws)\n\n",
                sigma, kTurnDeg, kTurnEnd - kRestEnd);
    std::printf("| filter | jitter at rest (deg) | lag on the turn (ms) | RMS error on the turn (deg) |\n");
    std::printf("|---|---|---|---|\n");
    std::printf("| none (raw tracker) | %.3f | %.0f | %.3f |\n", raw.jitter_deg, raw.lag_ms, raw.rms_deg);
    std::printf("| One Euro (min_cutoff %.2f Hz, beta %.3f, d_cutoff %.1f Hz) | %.3f | %.0f | %.3f |\n",
                params.min_cutoff_hz, params.beta, params.d_cutoff_hz, oe.jitter_deg, oe.lag_ms, oe.rms_deg);
    std::printf("| low-pass %.2f Hz (jitter matched to One Euro) | %.3f | %.0f | %.3f |\n", jitter_cutoff,
                lp_jitter.jitter_deg, lp_jitter.lag_ms, lp_jitter.rms_deg);
    std::printf("| low-pass %.2f Hz (lag matched to One Euro) | %.3f | %.0f | %.3f |\n\n", lag_cutoff,
                lp_lag.jitter_deg, lp_lag.lag_ms, lp_lag.rms_deg);
    std::printf("at equal jitter:  lag one-euro/low-pass = %.2f\n", oe.lag_ms / std::max(1.0, lp_jitter.lag_ms));
    std::printf("at equal lag:     jitter one-euro/low-pass = %.2f\n", oe.jitter_deg / lp_lag.jitter_deg);
    std::printf("vs raw:           jitter one-euro/raw = %.2f\n", oe.jitter_deg / raw.jitter_deg);
    return 0;
}
