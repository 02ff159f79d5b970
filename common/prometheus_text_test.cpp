// SPDX-License-Identifier: Apache-2.0
#include "common/prometheus_text.h"

#include <sys/stat.h>

#include <fstream>
#include <iterator>
#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

#include "tests/support/scratch_dir.h"

namespace mogao::prometheus {
namespace {

TEST(PrometheusText, NumbersAsTheFormatSpellsThem) {
    EXPECT_EQ(number(std::numeric_limits<double>::quiet_NaN()), "NaN");
    EXPECT_EQ(number(std::numeric_limits<double>::infinity()), "+Inf");
    EXPECT_EQ(number(-std::numeric_limits<double>::infinity()), "-Inf");
    EXPECT_EQ(number(1790000000.0), "1790000000");  // a Unix time, whole
    EXPECT_EQ(number(123456789.0), "123456789");
    EXPECT_EQ(number(0.25), "0.25");
    EXPECT_EQ(number(0.0), "0");
    EXPECT_EQ(number(-3.0), "-3");
}

TEST(PrometheusText, LabelValuesEscapeBackslashQuoteAndNewline) {
    EXPECT_EQ(label_value("a\\b\"c\nd"), "a\\\\b\\\"c\\nd");
    EXPECT_EQ(label_value("plain CN-1"), "plain CN-1");
}

TEST(PrometheusText, HistogramBucketsAreCumulativeAndLeInclusive) {
    Histogram h({0.1, 0.5, 1.0});
    // By hand: <= 0.1: 0.05, 0.1 (le is inclusive); <= 0.5: + 0.3; <= 1: + 1.0; +Inf: + 7.
    for (const double v : {0.05, 0.1, 0.3, 1.0, 7.0}) h.observe(v);
    h.observe(std::numeric_limits<double>::quiet_NaN());  // not counted
    h.observe(std::numeric_limits<double>::infinity());   // not counted
    EXPECT_EQ(h.cumulative_counts(), (std::vector<std::uint64_t>{2, 3, 4, 5}));
    EXPECT_EQ(h.count(), 5u);
    EXPECT_DOUBLE_EQ(h.sum(), 8.45);
    TextWriter w("mogao_test_");
    w.histogram("frame_seconds", "frame time", h, {{"appliance", "a1"}});
    EXPECT_EQ(w.text(),
              "# HELP mogao_test_frame_seconds frame time\n"
              "# TYPE mogao_test_frame_seconds histogram\n"
              "mogao_test_frame_seconds_bucket{appliance=\"a1\",le=\"0.1\"} 2\n"
              "mogao_test_frame_seconds_bucket{appliance=\"a1\",le=\"0.5\"} 3\n"
              "mogao_test_frame_seconds_bucket{appliance=\"a1\",le=\"1\"} 4\n"
              "mogao_test_frame_seconds_bucket{appliance=\"a1\",le=\"+Inf\"} 5\n"
              "mogao_test_frame_seconds_sum{appliance=\"a1\"} 8.45\n"
              "mogao_test_frame_seconds_count{appliance=\"a1\"} 5\n");
}

TEST(PrometheusText, HistogramRefusesBoundsThatAreNotIncreasingOrNotFinite) {
    EXPECT_THROW(Histogram({}), std::invalid_argument);
    EXPECT_THROW(Histogram({0.5, 0.5}), std::invalid_argument);
    EXPECT_THROW(Histogram({1.0, 0.5}), std::invalid_argument);
    EXPECT_THROW(Histogram({0.5, std::numeric_limits<double>::infinity()}), std::invalid_argument);
}

TEST(PrometheusText, GaugesAndCountersCarryHelpTypeAndEscapedLabels) {
    TextWriter w("p_");
    w.counter("rays_total", "rays traced", 42);
    w.family("info", "gauge", "build");
    w.sample("info", {{"version", "1.\"0\""}}, 1);
    EXPECT_EQ(w.text(),
              "# HELP p_rays_total rays traced\n# TYPE p_rays_total counter\np_rays_total 42\n"
              "# HELP p_info build\n# TYPE p_info gauge\np_info{version=\"1.\\\"0\\\"\"} 1\n");
}

// The units run with UMask=0077; node_exporter (another user) must still read the file.
TEST(PrometheusText, TextfileIsWorldReadableWhateverTheUmask) {
    const testing::ScratchDir dir("prometheus-text");
    const mode_t old = ::umask(077);
    write_textfile(dir.path() / "x.prom", "p_up 1\n");
    ::umask(old);
    struct stat st {};
    ASSERT_EQ(::stat((dir.path() / "x.prom").c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 0777, 0644u);
    std::ifstream in(dir.path() / "x.prom");
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "p_up 1\n");
    EXPECT_THROW(write_textfile(dir.path() / "missing-folder" / "x.prom", "p_up 1\n"), std::system_error);
}

}  // namespace
}  // namespace mogao::prometheus
