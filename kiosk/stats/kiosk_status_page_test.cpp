// SPDX-License-Identifier: Apache-2.0
// The technician's status page (kiosk/stats/kiosk_status_page.h) from the status file's own writer
// (kiosk_status_json): each figure in its element, absent or wrongly typed values as "unknown",
// text escaped, nothing outside the file referenced, the preview embedded, and bad status files
// refused with their name. The page in a real browser from a real kiosk: status_page_e2e_test.cpp.
#include "kiosk/stats/kiosk_status_page.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

#include "common/png_io.h"
#include "kiosk/stats/kiosk_status.h"
#include "kiosk/stats/status_page_test_util.h"

namespace mogao {
namespace {

namespace fs = std::filesystem;
using status_page_test::element_text;

class StatusPage : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("mogao-status-page-" + std::to_string(::getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    static KioskStatus showing() {
        KioskStatus s;
        s.written_ns = 1'795'869'005'000'000'000;  // 2026-11-28T12:30:05Z
        s.uptime_s = 3725.0;
        s.state = "showing";
        s.endpoint = "[fd00::1]:7443";
        s.connected = true;
        s.frames_shown = 123456;
        s.showing_request = 123470;
        s.fps = 29.94;
        s.latency_mean_ms = 83.26;
        s.latency_p95_ms = 131.04;
        s.calibration.source = "/etc/mogao/screen.mpcdi";
        s.calibration.loaded_ns = 1'795'860'000'000'000'000;
        s.calibration.refused = 1;
        s.calibration.last_error = "screen.mpcdi: projector 'p1': warp <grid> has 0 rows";
        s.calibration.last_error_ns = 1'795'868'000'000'000'000;
        s.certificates = {{"ca", "mogao museum CA", 1'830'000'000}, {"appliance", "kiosk-3", 1'797'000'000}};
        return s;
    }
    static StatusPageInput input(const nlohmann::json& status) {
        StatusPageInput in;
        in.status_file = "/run/mogao/kiosk-status.json";
        in.status = status;
        in.made_ns = 1'795'869'007'000'000'000;  // 2 s later
        return in;
    }
    fs::path dir_;
};

TEST_F(StatusPage, ShowsTheFiguresOfTheStatusFile) {
    const KioskStatus s = showing();
    const std::string html = kiosk_status_page_html(input(kiosk_status_json(s)));
    EXPECT_EQ(element_text(html, "state"), "showing");
    EXPECT_EQ(element_text(html, "written"), "2026-11-28T12:30:05Z");
    EXPECT_EQ(element_text(html, "age"), "2.0 s before this page was made");
    EXPECT_EQ(element_text(html, "frames-shown"), "123456");
    EXPECT_EQ(element_text(html, "fps"), "29.9 frames/s");
    EXPECT_EQ(element_text(html, "latency-mean"), "83.3 ms");
    EXPECT_EQ(element_text(html, "latency-p95"), "131.0 ms");
    EXPECT_EQ(element_text(html, "uptime"), "1 h 02 min 05 s");
    EXPECT_EQ(element_text(html, "farm-connected"), "yes");
    EXPECT_EQ(element_text(html, "farm-endpoint"), "[fd00::1]:7443");
    EXPECT_EQ(element_text(html, "calibration-source"), "/etc/mogao/screen.mpcdi");
    EXPECT_EQ(element_text(html, "calibration-refused"), "1");
    const auto refusal = element_text(html, "calibration-refusal");
    ASSERT_TRUE(refusal);
    EXPECT_NE(refusal->find(s.calibration.last_error), std::string::npos) << *refusal;
    EXPECT_NE(refusal->find(utc_text(s.calibration.last_error_ns)), std::string::npos) << *refusal;
    EXPECT_EQ(element_text(html, "cert-0-not-after"), utc_text(1'830'000'000'000'000'000));
    EXPECT_EQ(element_text(html, "cert-1-not-after"), utc_text(1'797'000'000'000'000'000));
    EXPECT_EQ(element_text(html, "last-error"), "none since start");
    EXPECT_EQ(element_text(html, "selfcal"), "off");
    // No calibration folder: the self-check is unknown and says why.
    EXPECT_EQ(element_text(html, "self-check-mean"), "unknown (no calibration folder given)");
}

TEST_F(StatusPage, AbsentOrWronglyTypedValuesShowAsUnknown) {
    nlohmann::json status = {{"state", "showing"}};
    std::string html = kiosk_status_page_html(input(status));
    for (const char* id : {"written",
                           "age",
                           "frames-shown",
                           "fps",
                           "latency-mean",
                           "latency-p95",
                           "uptime",
                           "farm-connected",
                           "farm-endpoint",
                           "calibration-source",
                           "calibration-loaded",
                           "calibration-swaps",
                           "calibration-refused",
                           "calibration-refusal",
                           "self-check-p95",
                           "self-check-gate",
                           "selfcal",
                           "last-error",
                           "certificates-none",
                           "on-wall"}) {
        EXPECT_EQ(element_text(html, id), "unknown") << id;
    }
    // Garbage in the right places: wrong types, a negative count, a non-object farm.
    status = {{"state", "showing"},
              {"fps", "fast"},
              {"frames_shown", -3},
              {"latency_p95_ms", true},
              {"farm", 7},
              {"written_utc", 12},
              {"calibration", {{"source", {1, 2}}}}};
    html = kiosk_status_page_html(input(status));
    for (const char* id :
         {"fps", "frames-shown", "latency-p95", "farm-connected", "farm-endpoint", "written", "calibration-source"}) {
        EXPECT_EQ(element_text(html, id), "unknown") << id;
    }
    EXPECT_EQ(html.find("fast"), std::string::npos);
    // An unknown state word is shown as it is, escaped, in the neutral colour.
    html = kiosk_status_page_html(input({{"state", "<b>odd</b>"}}));
    EXPECT_EQ(element_text(html, "state"), "<b>odd</b>");
    EXPECT_NE(html.find("b-unknown"), std::string::npos);
}

TEST_F(StatusPage, EscapesTextAndReferencesNothingOutsideTheFile) {
    KioskStatus s = showing();
    s.last_error = "<script>alert(1)</script> & \"more\"";
    s.last_error_ns = s.written_ns;
    s.on_wall = {"<img src=http://example.com/x.png>"};
    write_png(dir_ / "preview.png", Rgb8Image({8, 4}, 200));
    StatusPageInput in = input(kiosk_status_json(s));
    in.calibration = read_calibration_folder(dir_);
    const std::string html = kiosk_status_page_html(in);
    EXPECT_EQ(html.find("<script"), std::string::npos);
    EXPECT_EQ(html.find("<img src=http"), std::string::npos);
    for (const char* remote : {"src=\"http", "href=", "url(", "@import", "<link", "<iframe", "<object"}) {
        EXPECT_EQ(html.find(remote), std::string::npos) << remote;
    }
    EXPECT_EQ(*element_text(html, "last-error"), s.last_error + " (" + utc_text(s.written_ns) + ")");
    EXPECT_NE(html.find("src=\"data:image/png;base64,"), std::string::npos);
}

TEST_F(StatusPage, EmbedsThePreviewAndTheSelfCheckOfTheCalibrationFolder) {
    const fs::path cal = dir_ / "calibration";
    fs::create_directories(cal);
    const nlohmann::json report = {
        {"self_check", {{"mean_px", 0.2134}, {"p95_px", 0.4}, {"gate_max_mean_px", 0.65}, {"mean_mm", 0.31}}}};
    std::ofstream(cal / "report.json") << report.dump(2);
    Rgb8Image image({40, 20});
    for (std::size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = static_cast<std::uint8_t>(i * 13);
    write_png(cal / "preview.png", image);
    std::ifstream png(cal / "preview.png", std::ios::binary);
    const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(png)), {});
    StatusPageInput in = input(kiosk_status_json(showing()));
    in.calibration = read_calibration_folder(cal);
    EXPECT_TRUE(in.calibration.problems.empty());
    const std::string html = kiosk_status_page_html(in);
    EXPECT_EQ(element_text(html, "self-check-mean"), "0.213 px (0.31 mm on the screen)");
    EXPECT_EQ(element_text(html, "self-check-p95"), "0.400 px");
    EXPECT_EQ(element_text(html, "self-check-gate"), "0.65 px mean (passed)");
    EXPECT_NE(html.find("width=\"40\" height=\"20\""), std::string::npos);
    EXPECT_NE(html.find("base64," + base64_encode(bytes) + "\""), std::string::npos);
}

TEST_F(StatusPage, AGarbledCalibrationFolderIsNamedOnThePage) {
    const fs::path cal = dir_ / "calibration";
    fs::create_directories(cal);
    std::ofstream(cal / "report.json") << "{\"self_check\": ";
    std::ofstream(cal / "preview.png") << "not a png";
    StatusPageInput in = input(kiosk_status_json(showing()));
    in.calibration = read_calibration_folder(cal);
    ASSERT_EQ(in.calibration.problems.size(), 2u);
    EXPECT_NE(in.calibration.problems[0].find((cal / "report.json").string() + "' is not JSON"), std::string::npos);
    EXPECT_NE(in.calibration.problems[1].find((cal / "preview.png").string()), std::string::npos);
    const std::string html = kiosk_status_page_html(in);
    EXPECT_EQ(html.find("data:image"), std::string::npos);
    EXPECT_NE(html.find("is not JSON"), std::string::npos);
    EXPECT_EQ(element_text(html, "self-check-mean"), "unknown (no readable report.json)");
    // A folder that does not exist is named too.
    const CalibrationFolder none = read_calibration_folder(dir_ / "nowhere");
    ASSERT_EQ(none.problems.size(), 1u);
    EXPECT_NE(none.problems[0].find("nowhere' not found"), std::string::npos);
}

TEST_F(StatusPage, ABadStatusFileIsRefusedWithItsName) {
    const auto refused = [](const fs::path& file, const std::string& why) {
        try {
            (void)read_status_page_status(file);
            ADD_FAILURE() << file << " accepted";
        } catch (const StatusPageError& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find(file.string()), std::string::npos) << what;
            EXPECT_NE(what.find(why), std::string::npos) << what;
        }
    };
    refused(dir_ / "missing.json", "No such file");
    std::ofstream(dir_ / "empty.json").close();
    refused(dir_ / "empty.json", "is empty");
    std::ofstream(dir_ / "cut.json") << R"({"state": "showing", "frames_sh)";
    refused(dir_ / "cut.json", "is not JSON (at byte");
    std::ofstream(dir_ / "array.json") << "[1, 2]";
    refused(dir_ / "array.json", "is not a JSON object (found array)");
    std::ofstream(dir_ / "other.json") << R"({"format": "something else"})";
    refused(dir_ / "other.json", "is not the kiosk's status file");
    refused(dir_, "is not a regular file");
    // The writer's own file is read back whole.
    write_kiosk_status(dir_ / "status.json", showing());
    EXPECT_EQ(read_status_page_status(dir_ / "status.json"), kiosk_status_json(showing()));
}

TEST(StatusPageBase64, Rfc4648TestVectors) {
    const auto b64 = [](const std::string& s) { return base64_encode(std::vector<std::uint8_t>(s.begin(), s.end())); };
    EXPECT_EQ(b64(""), "");
    EXPECT_EQ(b64("f"), "Zg==");
    EXPECT_EQ(b64("fo"), "Zm8=");
    EXPECT_EQ(b64("foo"), "Zm9v");
    EXPECT_EQ(b64("foob"), "Zm9vYg==");
    EXPECT_EQ(b64("fooba"), "Zm9vYmE=");
    EXPECT_EQ(b64("foobar"), "Zm9vYmFy");
    EXPECT_EQ(base64_encode({0xff, 0xfe, 0x00}), "//4A");
}

}  // namespace
}  // namespace mogao
