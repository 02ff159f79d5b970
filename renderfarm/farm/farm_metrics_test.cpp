// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/farm_metrics.h"

#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <limits>
#include <map>
#include <regex>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "tests/support/scratch_dir.h"

namespace mogao {
namespace {

FrameStats frame(double render, std::vector<double> ranks) {
    FrameStats s;
    s.render_phase_seconds = render;
    s.rank_render_seconds = std::move(ranks);
    s.balance_efficiency = 0.75;
    s.rays = 1000;
    s.rays_per_second = 2.5e6;
    return s;
}

FarmCounters counters() {
    FarmCounters c;
    c.link.sessions_active = 2;
    c.link.requests_received = 40;
    c.link.requests_invalid = 1;
    c.link.frames_sent = 37;
    c.link.jpeg_bytes_sent = 123456789;
    c.link.connections.open = 3;
    c.link.connections.refused_per_address = 7;
    c.degraded = 3;
    c.superseded = 5;
    c.render_ranks = 2;
    // A CA name with a space and a quote: label values are escaped, not cut.
    c.link.crl_next_update_s = 1'780'000'000;
    c.link.certificates = {{"ca", "mogao \"farm\" CA", 2'000'000'000}, {"farm", "farm-1", 1'790'000'000}};
    return c;
}

// Sample lines "name{labels} value" -> value.
std::map<std::string, std::string> samples(const std::string& text) {
    std::map<std::string, std::string> out;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) {
        if (line.empty() || line[0] == '#') continue;
        const auto space = line.rfind(' ');
        out[line.substr(0, space)] = line.substr(space + 1);
    }
    return out;
}

constexpr double kNow = 1.7e9 + 5;

// Every line is a comment or a sample as the format defines them.
void expect_every_line_well_formed(const std::string& text) {
    const std::regex sample(R"(^[a-zA-Z_:][a-zA-Z0-9_:]*(\{[a-z_]+="([^"\\]|\\.)*"(,[a-z_]+="([^"\\]|\\.)*")*\})?)"
                            R"( (NaN|[+-]Inf|-?[0-9.e+-]+)$)");
    const std::regex comment(R"(^# (HELP|TYPE) mogao_farm_[a-z_]+ .+$)");
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);)
        EXPECT_TRUE(std::regex_match(line, sample) || std::regex_match(line, comment)) << line;
}

// With MOGAO_METRICS_SAMPLE_DIR set, the text is also left there for tests/monitoring_check.sh
// (promtool check metrics, and every name the alert rules and dashboard use).
void leave_sample(const std::string& text) {
    const char* dir = std::getenv("MOGAO_METRICS_SAMPLE_DIR");
    if (dir == nullptr || *dir == 0) return;
    std::ofstream(std::filesystem::path(dir) / "mogao-farm.prom") << text;
}

TEST(FarmMetrics, ExpositionTextHasEveryFamilyWithItsTypeAndValue) {
    FarmMetrics m("9.8.7");
    m.observe_frame(frame(0.1, {0.08, 0.06}), 0.2, 1.7e9, "kiosk-a");
    m.observe_frame(frame(0.3, {0.2, 0.3}), 0.4, 1.7e9 + 1, "kiosk-b");
    const std::string text = m.text(counters(), kNow);
    expect_every_line_well_formed(text);
    leave_sample(text);
    const auto s = samples(text);
    EXPECT_EQ(s.at("mogao_farm_up"), "1");
    EXPECT_EQ(s.at("mogao_farm_last_update_timestamp_seconds"), "1700000005");
    EXPECT_EQ(s.at("mogao_farm_build_info{version=\"9.8.7\"}"), "1");
    EXPECT_EQ(s.at("mogao_farm_frames_total"), "2");
    // Frame times 0.2 and 0.4 s, counted by hand into the buckets (le is inclusive).
    EXPECT_EQ(s.at("mogao_farm_frame_seconds_bucket{le=\"0.1\"}"), "0");
    EXPECT_EQ(s.at("mogao_farm_frame_seconds_bucket{le=\"0.25\"}"), "1");
    EXPECT_EQ(s.at("mogao_farm_frame_seconds_bucket{le=\"0.5\"}"), "2");
    EXPECT_EQ(s.at("mogao_farm_frame_seconds_bucket{le=\"+Inf\"}"), "2");
    EXPECT_EQ(s.at("mogao_farm_frame_seconds_count"), "2");
    EXPECT_DOUBLE_EQ(std::stod(s.at("mogao_farm_frame_seconds_sum")), 0.6);
    EXPECT_EQ(s.at("mogao_farm_render_phase_seconds_bucket{le=\"0.1\"}"), "1");
    EXPECT_EQ(s.at("mogao_farm_balance_efficiency_bucket{le=\"0.8\"}"), "2");
    EXPECT_EQ(s.at("mogao_farm_rays_total"), "2000");
    EXPECT_DOUBLE_EQ(std::stod(s.at("mogao_farm_rank_render_seconds_total{rank=\"1\"}")), 0.28);
    EXPECT_DOUBLE_EQ(std::stod(s.at("mogao_farm_rank_render_seconds_total{rank=\"2\"}")), 0.36);
    EXPECT_EQ(s.at("mogao_farm_appliance_frames_total{appliance=\"kiosk-b\"}"), "1");
    EXPECT_EQ(s.at("mogao_farm_appliance_frame_seconds_total{appliance=\"kiosk-a\"}"), "0.2");
    EXPECT_EQ(s.at("mogao_farm_requests_degraded_total"), "3");
    EXPECT_EQ(s.at("mogao_farm_jpeg_bytes_sent_total"), "123456789");
    EXPECT_EQ(s.at("mogao_farm_connections_open"), "3");
    EXPECT_EQ(s.at("mogao_farm_connections_refused_total{cap=\"max_unauthenticated_per_address\"}"), "7");
    EXPECT_EQ(s.at("mogao_farm_connections_refused_total{cap=\"max_connections\"}"), "0");
    EXPECT_NE(text.find("# TYPE mogao_farm_frames_total counter"), std::string::npos);
    EXPECT_NE(text.find("# TYPE mogao_farm_frame_seconds histogram"), std::string::npos);
    // The last-value gauge, the precomputed mean and the rate are gone: histograms and counters.
    for (const char* old :
         {"\nmogao_farm_frame_seconds ", "frame_seconds_mean", "rays_per_second", "rank_render_seconds{"})
        EXPECT_EQ(text.find(old), std::string::npos) << old;
    // Certificate expiry: Unix seconds as integers (not 2e+09), one sample per certificate.
    EXPECT_NE(text.find("# TYPE mogao_farm_certificate_not_after_seconds gauge"), std::string::npos);
    EXPECT_EQ(s.at("mogao_farm_certificate_not_after_seconds{role=\"farm\",name=\"farm-1\"}"), "1790000000");
    EXPECT_EQ(s.at("mogao_farm_crl_next_update_seconds"), "1780000000");
    EXPECT_EQ(s.at("mogao_farm_certificate_not_after_seconds{role=\"ca\",name=\"mogao \\\"farm\\\" CA\"}"),
              "2000000000");
}

TEST(FarmMetrics, NoCertificateOrRevocationFamilyWithoutThem) {
    FarmCounters c = counters();
    c.link.certificates.clear();
    c.link.crl_next_update_s = 0;
    EXPECT_EQ(FarmMetrics("0").text(c, kNow).find("certificate_not_after"), std::string::npos);
    EXPECT_EQ(FarmMetrics("0").text(c, kNow).find("crl_next_update"), std::string::npos);
}

TEST(FarmMetrics, UnmeasuredTimesLeaveCountersAndHistogramsUntouched) {
    FarmMetrics m("0");
    FrameStats f = frame(0.1, {std::numeric_limits<double>::quiet_NaN(), 0.05});
    m.observe_frame(f, std::numeric_limits<double>::quiet_NaN(), 0);
    const auto s = samples(m.text(counters(), kNow));
    EXPECT_EQ(s.at("mogao_farm_rank_render_seconds_total{rank=\"1\"}"), "0");
    EXPECT_EQ(s.at("mogao_farm_rank_render_seconds_total{rank=\"2\"}"), "0.05");
    EXPECT_EQ(s.at("mogao_farm_frame_seconds_count"), "0");
    EXPECT_EQ(s.at("mogao_farm_frames_total"), "1");
}

TEST(FarmMetrics, ApplianceLabelsAreBoundedTheRestCountedAsOther) {
    FarmMetrics m("0");
    const std::size_t n = FarmMetrics::kMaxApplianceLabels + 8;
    for (std::size_t i = 0; i < n; ++i) m.observe_frame(frame(0.1, {0.1}), 0.1, 0, "kiosk-" + std::to_string(i));
    m.observe_frame(frame(0.1, {0.1}), 0.1, 0, "kiosk-0");  // seen before the cap: keeps its own series
    m.observe_frame(frame(0.1, {0.1}), 0.1, 0, "");         // its session closed before the frame
    const auto s = samples(m.text(counters(), kNow));
    std::size_t series = 0;
    for (const auto& [name, value] : s) series += name.starts_with("mogao_farm_appliance_frames_total{") ? 1 : 0;
    EXPECT_EQ(series, FarmMetrics::kMaxApplianceLabels + 2);  // + "other" + "unknown"
    EXPECT_EQ(s.at("mogao_farm_appliance_frames_total{appliance=\"other\"}"), "8");
    EXPECT_EQ(s.at("mogao_farm_appliance_frames_total{appliance=\"kiosk-0\"}"), "2");
    EXPECT_EQ(s.at("mogao_farm_appliance_frames_total{appliance=\"unknown\"}"), "1");
    EXPECT_EQ(s.count("mogao_farm_appliance_frames_total{appliance=\"kiosk-39\"}"), 0u);
}

std::string read_text(const std::filesystem::path& file) {
    std::ifstream in(file);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// An exception leaving the serve loop unwinds the file's owner: it says up 0, not a stale 1.
TEST(FarmMetricsFile, SaysDownWhenItsOwnerGoesAway) {
    const testing::ScratchDir dir("farm-metrics-file");
    const auto file = dir.path() / "mogao-farm.prom";
    FarmMetrics m("0");
    {
        FarmMetricsFile f(file);
        f.update(m, counters());
        EXPECT_EQ(samples(read_text(file)).at("mogao_farm_up"), "1");
    }
    const auto s = samples(read_text(file));
    EXPECT_EQ(s.at("mogao_farm_up"), "0");
    EXPECT_EQ(s.at("mogao_farm_requests_degraded_total"), "3");  // the counters as last written
}

extern "C" void stop_signal_for_test(int) { FarmMetricsFile::on_stop_signal(); }

// SIGTERM (systemd's stop, mpirun's) reaches the admin, which may be SIGKILLed before its loop sees
// it: the handler itself writes up 0, and no later update writes 1 again. A real signal here.
TEST(FarmMetricsFile, SaysDownFromTheStopSignalsHandler) {
    const testing::ScratchDir dir("farm-metrics-signal");
    const auto file = dir.path() / "mogao-farm.prom";
    FarmMetrics m("0");
    FarmMetricsFile f(file);
    f.update(m, counters());
    struct sigaction action {
    }, previous{};
    action.sa_handler = stop_signal_for_test;
    ASSERT_EQ(::sigaction(SIGUSR2, &action, &previous), 0);
    ::raise(SIGUSR2);
    ::sigaction(SIGUSR2, &previous, nullptr);
    EXPECT_EQ(samples(read_text(file)).at("mogao_farm_up"), "0");
    f.update(m, counters());  // the loop's next round, before it saw the stop
    EXPECT_EQ(samples(read_text(file)).at("mogao_farm_up"), "0");
}

// The stop signal may come while the loop's update is writing up 1 (it finds the file up 1, writes
// its down text, and the update's rename then puts up 1 back); mpirun SIGKILLs the admin a second
// later, before any further update. The update that was interrupted must leave up 0 itself. The
// "signal" comes from another thread at a random moment of a stream of updates; each round ends
// after the update it interrupted, as a SIGKILL would end it.
TEST(FarmMetricsFile, SaysDownWhenTheStopComesDuringAnUpdate) {
    const testing::ScratchDir dir("farm-metrics-race");
    FarmMetrics m("0");
    int up_left = 0;
    for (int round = 0; round < 200; ++round) {
        const auto file = dir.path() / ("round-" + std::to_string(round) + ".prom");
        FarmMetricsFile f(file);
        f.update(m, counters());
        std::atomic<bool> killed{false};
        std::atomic<int> updates{0};
        std::thread loop([&] {
            while (!killed.load()) {
                f.update(m, counters());
                updates.fetch_add(1);
            }
        });
        while (updates.load() < 3 + round % 7) std::this_thread::yield();
        FarmMetricsFile::on_stop_signal();
        killed = true;
        loop.join();
        if (samples(read_text(file)).at("mogao_farm_up") != "0") ++up_left;
    }
    EXPECT_EQ(up_left, 0) << "rounds whose file said up 1 after the stop";
}

// std::terminate (an exception on a gRPC thread, noexcept violated) still leaves up 0 behind. The
// death test runs it in a child process; the file it wrote is read here.
TEST(FarmMetricsFile, SaysDownOnTerminate) {
    const testing::ScratchDir dir("farm-metrics-terminate");
    const auto file = dir.path() / "mogao-farm.prom";
    EXPECT_DEATH(
        {
            FarmMetrics m("0");
            FarmMetricsFile f(file);
            f.update(m, counters());
            std::terminate();
        },
        "");
    EXPECT_EQ(samples(read_text(file)).at("mogao_farm_up"), "0");
}

std::string run(const std::string& command) {
    std::string out;
    FILE* pipe = ::popen(command.c_str(), "r");
    if (!pipe) return out;
    std::array<char, 4096> buffer{};
    for (std::size_t n; (n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0;) out.append(buffer.data(), n);
    ::pclose(pipe);
    return out;
}

int free_tcp_port() {
    const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof a;
    ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
    ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
    ::close(fd);
    return ntohs(a.sin_port);
}

// The real consumer: Debian's prometheus-node-exporter reads the file through its textfile
// collector and serves it; a file it cannot parse shows as node_textfile_scrape_error 1.
TEST(FarmMetrics, NodeExporterTextfileCollectorReadsTheFile) {
    if (run("command -v prometheus-node-exporter").empty())
        GTEST_SKIP() << "prometheus-node-exporter is not installed (.ci/deps installs it)";
    const testing::ScratchDir dir("farm-metrics");
    FarmMetrics m("0");
    m.observe_frame(frame(0.1, {0.08, 0.06}), 0.2, 1.7e9);
    m.write(dir.path() / "mogao-farm.prom", counters(), kNow);
    const int port = free_tcp_port();
    const std::string exporter =
        "prometheus-node-exporter --collector.disable-defaults --collector.textfile "
        "--collector.textfile.directory=" +
        dir.path().string() + " --web.listen-address=127.0.0.1:" + std::to_string(port) + " > " +
        (dir.path() / "exporter.log").string() + " 2>&1 & echo $!";
    const std::string pid = run(exporter);
    std::string scraped;
    for (int i = 0; i < 100 && scraped.find("mogao_farm_up") == std::string::npos; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        scraped = run("curl -s http://127.0.0.1:" + std::to_string(port) + "/metrics");
    }
    run("kill " + pid);
    std::ifstream log(dir.path() / "exporter.log");
    const std::string log_text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
    ASSERT_NE(scraped.find("mogao_farm_up 1"), std::string::npos) << "exporter log:\n" << log_text;
    EXPECT_NE(scraped.find("mogao_farm_rank_render_seconds_total{rank=\"2\"} 0.06"), std::string::npos);
    EXPECT_NE(scraped.find("mogao_farm_frame_seconds_bucket{le=\"0.25\"} 1"), std::string::npos) << scraped;
    EXPECT_NE(scraped.find("mogao_farm_jpeg_bytes_sent_total 1.23456789e+08"), std::string::npos) << scraped;
    EXPECT_NE(scraped.find("node_textfile_scrape_error 0"), std::string::npos) << scraped;
    EXPECT_NE(scraped.find("mogao_farm_certificate_not_after_seconds{name=\"farm-1\",role=\"farm\"} 1.79e+09"),
              std::string::npos)
        << scraped;
}

}  // namespace
}  // namespace mogao
