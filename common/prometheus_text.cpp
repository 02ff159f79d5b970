// SPDX-License-Identifier: Apache-2.0
#include "common/prometheus_text.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <span>
#include <stdexcept>

#include <fmt/format.h>

#include "common/file_io.h"

namespace mogao::prometheus {

std::string number(double value) {
    if (std::isnan(value)) return "NaN";
    if (std::isinf(value)) return value > 0 ? "+Inf" : "-Inf";
    // fmt's shortest round-trip form, except that whole numbers stay whole up to 1e16.
    if (value == std::floor(value) && std::abs(value) < 1e16) return fmt::format("{:.0f}", value);
    return fmt::format("{}", value);
}

std::string label_value(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    for (const char c : text) {
        if (c == '\n') {
            out += "\\n";
            continue;
        }
        if (c == '\\' || c == '"') out += '\\';
        out += c;
    }
    return out;
}

Histogram::Histogram(std::vector<double> upper_bounds) : bounds_(std::move(upper_bounds)) {
    if (bounds_.empty()) throw std::invalid_argument("prometheus::Histogram: no bucket bounds");
    for (std::size_t i = 0; i < bounds_.size(); ++i) {
        if (!std::isfinite(bounds_[i]) || (i > 0 && !(bounds_[i] > bounds_[i - 1])))
            throw std::invalid_argument("prometheus::Histogram: bucket bounds must be finite and strictly increasing");
    }
    per_bucket_.assign(bounds_.size() + 1, 0);
}

void Histogram::observe(double value) {
    if (!std::isfinite(value)) return;
    // The first bucket whose upper bound is >= value (le: less than or equal).
    const auto it = std::lower_bound(bounds_.begin(), bounds_.end(), value);
    ++per_bucket_[static_cast<std::size_t>(it - bounds_.begin())];
    ++count_;
    sum_ += value;
}

std::vector<std::uint64_t> Histogram::cumulative_counts() const {
    std::vector<std::uint64_t> out(per_bucket_.size());
    std::uint64_t running = 0;
    for (std::size_t i = 0; i < per_bucket_.size(); ++i) out[i] = running += per_bucket_[i];
    return out;
}

void TextWriter::family(std::string_view name, std::string_view type, std::string_view help) {
    fmt::format_to(std::back_inserter(text_), "# HELP {0}{1} {2}\n# TYPE {0}{1} {3}\n", prefix_, name, help, type);
}

void TextWriter::sample(std::string_view name, const Labels& labels, double value) {
    text_ += prefix_;
    text_ += name;
    if (!labels.empty()) {
        text_ += '{';
        for (std::size_t i = 0; i < labels.size(); ++i) {
            fmt::format_to(std::back_inserter(text_), "{}{}=\"{}\"", i == 0 ? "" : ",", labels[i].first,
                           label_value(labels[i].second));
        }
        text_ += '}';
    }
    text_ += ' ';
    text_ += number(value);
    text_ += '\n';
}

void TextWriter::gauge(std::string_view name, std::string_view help, double value) {
    family(name, "gauge", help);
    sample(name, {}, value);
}

void TextWriter::counter(std::string_view name, std::string_view help, double value) {
    family(name, "counter", help);
    sample(name, {}, value);
}

void TextWriter::histogram(std::string_view name, std::string_view help, const Histogram& h, const Labels& labels) {
    family(name, "histogram", help);
    histogram_series(name, h, labels);
}

void TextWriter::histogram_series(std::string_view name, const Histogram& h, const Labels& labels) {
    const std::string base(name);
    const std::vector<std::uint64_t> cumulative = h.cumulative_counts();
    Labels with_le = labels;
    with_le.emplace_back("le", "");
    for (std::size_t i = 0; i < cumulative.size(); ++i) {
        with_le.back().second = i < h.upper_bounds().size() ? number(h.upper_bounds()[i]) : "+Inf";
        sample(base + "_bucket", with_le, static_cast<double>(cumulative[i]));
    }
    sample(base + "_sum", labels, h.sum());
    sample(base + "_count", labels, static_cast<double>(h.count()));
}

void write_textfile(const std::filesystem::path& file, const std::string& text) {
    write_file_atomically(file, std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()), 0644);
}

}  // namespace mogao::prometheus
