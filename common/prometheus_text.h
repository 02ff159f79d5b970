// SPDX-License-Identifier: Apache-2.0
// The Prometheus text exposition format, version 0.0.4
// (https://prometheus.io/docs/instrumenting/exposition_formats/), as the farm and the kiosk write it
// for node_exporter's textfile collector: one writer so that both spell numbers, label values and
// histograms alike, and one file writer that a node_exporter running as another user can read.
//
// Conventions (https://prometheus.io/docs/practices/naming/, .../practices/histograms/): base units
// (seconds, bytes), counters end in _total, a distribution is a histogram (cumulative _bucket{le=...}
// series, _sum, _count) rather than a last value or a precomputed mean, so that a dashboard can
// take quantiles and means over any window with histogram_quantile() and rate(_sum)/rate(_count).
// Errors: Histogram's constructor throws std::invalid_argument for bounds that are empty, not
// finite or not strictly increasing; write_textfile throws std::system_error naming the file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace mogao::prometheus {

// A sample value as the format spells it (Go's ParseFloat: NaN, +Inf, -Inf; integers below 1e16
// in full, e.g. a Unix time 1790000000, never 1.79e+09).
[[nodiscard]] std::string number(double value);

// A label value escaped as the format requires: backslash, double quote, line feed.
[[nodiscard]] std::string label_value(std::string_view text);

using Labels = std::vector<std::pair<std::string, std::string>>;

// A cumulative histogram with fixed upper bounds (the +Inf bucket is implicit). A NaN or infinite
// observation is not counted (it would make _sum NaN or infinite for ever, and every rate with it).
class Histogram {
public:
    explicit Histogram(std::vector<double> upper_bounds);
    void observe(double value);
    [[nodiscard]] const std::vector<double>& upper_bounds() const { return bounds_; }
    // Observations <= upper_bounds()[i], cumulative; one more entry at the end for +Inf (= count()).
    [[nodiscard]] std::vector<std::uint64_t> cumulative_counts() const;
    [[nodiscard]] std::uint64_t count() const { return count_; }
    [[nodiscard]] double sum() const { return sum_; }

private:
    std::vector<double> bounds_;
    std::vector<std::uint64_t> per_bucket_;  // not cumulative; the last one is (bounds_.back(), +Inf)
    std::uint64_t count_ = 0;
    double sum_ = 0.0;
};

// Builds one exposition text. Every metric name is `prefix` + the name given; each family's HELP
// and TYPE lines come once, before its samples.
class TextWriter {
public:
    explicit TextWriter(std::string prefix) : prefix_(std::move(prefix)) {}

    // HELP and TYPE ("counter", "gauge", "histogram") of a family whose samples follow.
    void family(std::string_view name, std::string_view type, std::string_view help);
    // One sample of the family last begun; `name` may carry a suffix (_bucket, _sum, _count).
    void sample(std::string_view name, const Labels& labels, double value);

    // A family with one sample and no labels.
    void gauge(std::string_view name, std::string_view help, double value);
    void counter(std::string_view name, std::string_view help, double value);
    // A histogram family; `labels` go on every series, before le.
    void histogram(std::string_view name, std::string_view help, const Histogram& h, const Labels& labels = {});
    // Only the series of a histogram family already begun (several label sets in one family).
    void histogram_series(std::string_view name, const Histogram& h, const Labels& labels);

    [[nodiscard]] const std::string& text() const { return text_; }

private:
    std::string prefix_;
    std::string text_;
};

// Writes `text` atomically (common/file_io.h: temporary + fsync + rename) with mode 0644 whatever
// the process umask: node_exporter runs as its own user (Debian: prometheus) and must read it, while
// mogao's units run with UMask=0077.
void write_textfile(const std::filesystem::path& file, const std::string& text);

}  // namespace mogao::prometheus
