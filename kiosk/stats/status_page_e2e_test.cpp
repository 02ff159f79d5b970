// SPDX-License-Identifier: Apache-2.0
// The technician's status page end to end, in a real browser: the real `mogao-kiosk` binary runs
// on headless outputs (Mesa surfaceless EGL) with a calibration made by `mogao-calibrate-sim rig`'s
// job on the standard virtual rig at quarter resolution (its folder: calibration.mpcdi, report.json
// with the self-check, preview.png), fed over the real link (gRPC + mutual TLS over [::1]) by a
// TEST DOUBLE of the farm (a LinkServer answering every view request with one textured frame).
// While it shows, its installed MPCDI is replaced by a broken file, which it refuses (the refusal
// reason goes into its status file). Its status file, as its own writer wrote it, then goes through
// the service mode's status step (`mogao-service status-page DIR`: the status file and status.html
// from `mogao-kiosk-status-page`, as onto the stick), and the page through headless Chromium: --dump-dom must hold the
// figures of the status file and report.json, parsed here apart from the page's code, and the
// --screenshot must be a 1280x900 PNG that is not blank. The screenshot, page, DOM and status file
// are copied to MOGAO_STATUS_PAGE_OUT (the build folder's kiosk/status-page/).
// Without Chromium (chromium or chromium-browser on PATH, or MOGAO_CHROMIUM) the test skips (exit
// 77); CI installs it (.ci/deps) and counts a skip as a failure (.ci/check-skips).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <set>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "appliance/autocal/calibrate_job.h"
#include "common/jpeg_codec.h"
#include "common/png_io.h"
#include "kiosk/config/config_overrides.h"
#include "kiosk/stats/status_page_test_util.h"
#include "renderfarm/link/link_test_support.h"
#include "tests/support/child_process.h"

extern char** environ;

namespace mogao {
namespace {

namespace fs = std::filesystem;
using status_page_test::element_text;
using Clock = std::chrono::steady_clock;

constexpr ImageSize kContent{960, 540};

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// The browser: MOGAO_CHROMIUM, else chromium or chromium-browser on PATH; empty: none.
std::string find_chromium() {
    if (const char* env = std::getenv("MOGAO_CHROMIUM"); env != nullptr && *env != '\0') return env;
    const char* path = std::getenv("PATH");
    std::istringstream dirs(path != nullptr ? path : "/usr/bin:/bin");
    std::string dir;
    while (std::getline(dirs, dir, ':')) {
        for (const char* name : {"chromium", "chromium-browser"}) {
            const fs::path p = fs::path(dir) / name;
            if (::access(p.c_str(), X_OK) == 0) return p.string();
        }
    }
    return "";
}

// Runs a program (PATH searched) to its end, stdout and stderr into files: its exit status.
int run(const std::vector<std::string>& args, const fs::path& out, const fs::path& err) {
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&actions, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    pid_t pid = -1;
    const int rc = ::posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) return 127;
    int status = 0;
    ::waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

using mogao::testing::ChildProcess;

// The calibration folder as `mogao-calibrate-sim rig --rig rigs/standard.toml --scale 0.25` leaves it.
nlohmann::json calibrate(const fs::path& out) {
    autocal::CalibrateJob job;
    job.rig = std::string(MOGAO_SOURCE_DIR) + "/rigs/standard.toml";
    job.out = out;
    job.scale = 0.25;
    job.content = kContent;
    job.options.warp_step_px = 4;
    return autocal::run_calibrate_job(job);
}

Rgb8Image textured_content() {
    Rgb8Image image(kContent);
    for (int y = 0; y < kContent.height; ++y) {
        for (int x = 0; x < kContent.width; ++x) {
            std::uint8_t* p = image.at(x, y);
            const bool check = ((x / 60) + (y / 60)) % 2 == 0;
            p[0] = static_cast<std::uint8_t>(check ? 200 : 60 + x % 120);
            p[1] = static_cast<std::uint8_t>(check ? 170 : 40 + y % 150);
            p[2] = static_cast<std::uint8_t>(check ? 120 : 90);
        }
    }
    return image;
}

// Polls the status file until `done` holds for a complete (parsed) file; returns that file's text.
std::string wait_status(const fs::path& file, ChildProcess& kiosk,
                        const std::function<bool(const nlohmann::json&)>& done) {
    const auto guard = Clock::now() + std::chrono::seconds(60);
    while (!kiosk.exited() && Clock::now() < guard) {
        const std::string text = slurp(file);
        const auto status = nlohmann::json::parse(text, nullptr, false);
        if (!status.is_discarded() && status.is_object() && done(status)) return text;
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return "";
}

std::size_t distinct_colours(const Rgb8Image& image) {
    std::set<std::uint32_t> colours;
    for (std::size_t i = 0; i + 2 < image.pixels.size(); i += 3) {
        colours.insert((std::uint32_t{image.pixels[i]} << 16) | (std::uint32_t{image.pixels[i + 1]} << 8) |
                       image.pixels[i + 2]);
    }
    return colours.size();
}

std::string base64_of_file(const fs::path& file) {  // the test's own encoder (RFC 4648), apart from the page's
    const std::string bytes = slurp(file);
    const char* abc = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    std::uint32_t acc = 0;
    int bits = 0;
    for (const unsigned char c : bytes) {
        acc = (acc << 8) | c;
        bits += 8;
        while (bits >= 6) out.push_back(abc[(acc >> (bits -= 6)) & 63u]);
    }
    if (bits > 0) out.push_back(abc[(acc << (6 - bits)) & 63u]);
    while (out.size() % 4 != 0) out.push_back('=');
    return out;
}

class StatusPageE2e : public ::testing::Test {
protected:
    void SetUp() override {
        chromium_ = find_chromium();
        if (chromium_.empty()) {
            std::cout << "SKIP: no Chromium (apt-get install chromium; CI installs it with .ci/deps)\n";
            GTEST_SKIP() << "no chromium or chromium-browser on PATH (MOGAO_CHROMIUM names another)";
        }
        if (!testing::ipv6_loopback_available()) GTEST_SKIP() << "no IPv6 loopback ([::1]) for the link";
    }
    std::string chromium_;
    testing::TempDir tmp_;
};

// Runs the kiosk on the calibration folder's MPCDI (copied as `mogao-calibrate --install` leaves it)
// until it has shown frames and refused a broken MPCDI written over it; the status file's text then
// (empty: it never got there).
std::string run_kiosk(const fs::path& dir, const fs::path& calibration) {
    fs::create_directories(dir);
    fs::copy_file(calibration / "calibration.mpcdi", dir / "screen.mpcdi");
    const auto& pki = testing::TestPki::get();
    std::ofstream(dir / "ca.pem") << pki.ca.cert_pem;
    std::ofstream(dir / "a.pem") << pki.museum1.cert_pem;
    std::ofstream(dir / "a.key") << pki.museum1.key_pem;
    RenderedFrame frame;
    frame.size = kContent;
    frame.jpeg = JpegEncoder().encode(textured_content(), 90);
    LinkServer farm(testing::test_server_options(), [&frame](const ViewRequest&) { return frame; });
    const std::string toml = apply_config_overrides(
        kiosk_example_toml(),
        {"farm.endpoint=\"" + farm.endpoint().to_string() + "\"", R"(farm.ca="ca.pem")", R"(farm.cert="a.pem")",
         R"(farm.key="a.key")", "display.rate_hz=30", R"(outputs.backend="headless")", "outputs.composite=false",
         R"(calibration.source="screen.mpcdi")", "calibration.watch=true", R"(quality.content="960x540")",
         "navigation.path_frames=10", "stats.file=", R"(stats.status_file="status.json")",
         "stats.status_period_s=0.2"});
    std::ofstream(dir / "kiosk.toml") << toml;
    ChildProcess kiosk({MOGAO_KIOSK_BINARY, "--config", (dir / "kiosk.toml").string(), "--duration-s", "120"});
    const fs::path status = dir / "status.json";
    if (wait_status(status, kiosk, [](const nlohmann::json& j) {
            return j.value("frames_shown", 0) >= 20 && j.value("fps", 0.0) > 0.0;
        }).empty()) {
        return "";
    }
    std::ofstream(dir / "broken.mpcdi.tmp") << "not an MPCDI file";
    fs::rename(dir / "broken.mpcdi.tmp", dir / "screen.mpcdi");  // as an installer replaces it: whole
    std::string text = wait_status(status, kiosk, [](const nlohmann::json& j) {
        return j.contains("calibration") && j["calibration"].value("refused", 0) >= 1 &&
               j.value("frames_shown", 0) >= 30;
    });
    EXPECT_EQ(kiosk.stop(), 0) << "the kiosk's exit after SIGTERM";
    return text;
}

// The page through headless Chromium: the screenshot and the DOM (false: Chromium failed).
bool browse(const std::string& chromium, const fs::path& page, const fs::path& dir) {
    const std::vector<std::string> common = {"timeout",
                                             "120",
                                             chromium,
                                             "--headless",
                                             "--no-sandbox",
                                             "--disable-gpu",
                                             "--user-data-dir=" + (dir / "chromium-profile").string()};
    std::vector<std::string> shot = common;
    shot.insert(shot.end(),
                {"--screenshot=" + (dir / "status.png").string(), "--window-size=1280,900", "file://" + page.string()});
    std::vector<std::string> dom = common;
    dom.insert(dom.end(), {"--dump-dom", "file://" + page.string()});
    const int a = run(shot, dir / "screenshot.out", dir / "screenshot.err");
    const int b = run(dom, dir / "dom.html", dir / "dom.err");
    EXPECT_EQ(a, 0) << "chromium --screenshot: " << slurp(dir / "screenshot.err");
    EXPECT_EQ(b, 0) << "chromium --dump-dom: " << slurp(dir / "dom.err");
    return a == 0 && b == 0;
}

// What the DOM must show: the status file's and report.json's figures, parsed here.
void expect_figures(const std::string& dom, const nlohmann::json& s, const nlohmann::json& report) {
    EXPECT_EQ(element_text(dom, "state"), s["state"].get<std::string>());
    EXPECT_EQ(element_text(dom, "written"), s["written_utc"].get<std::string>());
    EXPECT_EQ(element_text(dom, "frames-shown"), std::to_string(s["frames_shown"].get<std::uint64_t>()));
    EXPECT_EQ(element_text(dom, "fps"), fmt::format("{:.1f} frames/s", s["fps"].get<double>()));
    EXPECT_EQ(element_text(dom, "latency-mean"), fmt::format("{:.1f} ms", s["latency_mean_ms"].get<double>()));
    EXPECT_EQ(element_text(dom, "latency-p95"), fmt::format("{:.1f} ms", s["latency_p95_ms"].get<double>()));
    EXPECT_EQ(element_text(dom, "farm-endpoint"), s["farm"]["endpoint"].get<std::string>());
    EXPECT_EQ(element_text(dom, "farm-connected"), s["farm"]["connected"].get<bool>() ? "yes" : "no");
    EXPECT_EQ(element_text(dom, "calibration-source"), s["calibration"]["source"].get<std::string>());
    EXPECT_EQ(element_text(dom, "calibration-refused"), std::to_string(s["calibration"]["refused"].get<int>()));
    const std::string reason = s["calibration"]["last_error"].get<std::string>();
    EXPECT_FALSE(reason.empty());
    EXPECT_NE(element_text(dom, "calibration-refusal").value_or("").find(reason), std::string::npos) << reason;
    const nlohmann::json& check = report["self_check"];
    EXPECT_EQ(element_text(dom, "self-check-mean")
                  .value_or("")
                  .rfind(fmt::format("{:.3f} px", check["mean_px"].get<double>()), 0),
              0u);
    EXPECT_EQ(element_text(dom, "self-check-p95"), fmt::format("{:.3f} px", check["p95_px"].get<double>()));
    ASSERT_FALSE(s["certificates"].empty());
    for (std::size_t k = 0; k < s["certificates"].size(); ++k) {
        EXPECT_EQ(element_text(dom, "cert-" + std::to_string(k) + "-not-after"),
                  s["certificates"][k]["not_after_utc"].get<std::string>());
    }
    EXPECT_EQ(dom.find("<script"), std::string::npos);
}

TEST_F(StatusPageE2e, ARealKiosksStatusShowsItsFiguresInChromium) {
    const fs::path dir = tmp_.path();
    const nlohmann::json returned = calibrate(dir / "calibration");
    ASSERT_TRUE(returned.contains("self_check"));
    const std::string status_text = run_kiosk(dir / "kiosk", dir / "calibration");
    ASSERT_FALSE(status_text.empty()) << "the kiosk showed no frames, or never refused the broken MPCDI";
    const fs::path status_file = dir / "kiosk-status.json";
    std::ofstream(status_file) << status_text;
    // What the service mode's status action puts on the stick, written into a folder.
    const fs::path stick = dir / "stick";
    fs::create_directories(stick);
    ASSERT_EQ(run({"env", "MOGAO_SERVICE_WALL=", "MOGAO_SERVICE_STATUS_FILE=" + status_file.string(),
                   "MOGAO_SERVICE_CALIBRATION=" + (dir / "calibration").string(),
                   std::string("MOGAO_SERVICE_STATUS_PAGE=") + MOGAO_STATUS_PAGE_BINARY, "bash",
                   std::string(MOGAO_SOURCE_DIR) + "/kiosk/service_mode/mogao-service", "status-page", stick.string()},
                  dir / "service.out", dir / "service.err"),
              0)
        << slurp(dir / "service.out") << slurp(dir / "service.err");
    EXPECT_EQ(slurp(stick / "kiosk-status.json"), status_text) << "the status file beside the page";
    const fs::path page = stick / "status.html";
    fs::copy_file(page, dir / "status.html");
    const bool browsed = browse(chromium_, page, dir);
    // Kept for people: the screenshot, page, DOM and status file in the build folder.
    const fs::path keep = MOGAO_STATUS_PAGE_OUT;
    fs::create_directories(keep);
    for (const char* name : {"status.png", "status.html", "dom.html", "kiosk-status.json"}) {
        if (fs::exists(dir / name)) fs::copy_file(dir / name, keep / name, fs::copy_options::overwrite_existing);
    }
    std::cout << "status page screenshot: " << (keep / "status.png").string() << "\n";
    ASSERT_TRUE(browsed);
    const std::string dom = slurp(dir / "dom.html");
    expect_figures(dom, nlohmann::json::parse(status_text),
                   nlohmann::json::parse(slurp(dir / "calibration" / "report.json")));
    EXPECT_NE(dom.find("src=\"data:image/png;base64," + base64_of_file(dir / "calibration" / "preview.png") + "\""),
              std::string::npos)
        << "the calibration's preview.png, embedded";
    const Rgb8Image shot = read_png(dir / "status.png");
    EXPECT_EQ(shot.size.width, 1280);
    EXPECT_EQ(shot.size.height, 900);
    const std::size_t colours = distinct_colours(shot);
    std::cout << "screenshot: " << colours << " distinct colours\n";
    EXPECT_GT(colours, 200u) << "the screenshot looks blank";
}

// Bad input through the program: a clear error naming the file, exit 1, no page.
TEST(StatusPageProgram, AMissingOrGarbledStatusFileIsNamed) {
    const testing::TempDir tmp;
    const fs::path dir = tmp.path();
    const fs::path page = dir / "status.html";
    const auto refuses = [&](const fs::path& status, const std::string& why) {
        const int rc = run({MOGAO_STATUS_PAGE_BINARY, "--status", status.string(), "--out", page.string()}, dir / "out",
                           dir / "err");
        const std::string err = slurp(dir / "err");
        EXPECT_EQ(rc, 1) << err;
        EXPECT_NE(err.find(status.string()), std::string::npos) << err;
        EXPECT_NE(err.find(why), std::string::npos) << err;
        EXPECT_FALSE(fs::exists(page));
    };
    refuses(dir / "kiosk-status.json", "No such file");
    std::ofstream(dir / "garbled.json") << "{\"state\": \"showing\", \"frames_";
    refuses(dir / "garbled.json", "is not JSON");
    EXPECT_EQ(run({MOGAO_STATUS_PAGE_BINARY, "--status", (dir / "garbled.json").string()}, dir / "out", dir / "err"), 2)
        << "--out is required";
}

}  // namespace
}  // namespace mogao
