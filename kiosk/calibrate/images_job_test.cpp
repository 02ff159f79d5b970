// SPDX-License-Identifier: Apache-2.0
// The calibration from captured images: `patterns` writes the pattern set, the virtual rig films
// each written PNG (SIMULATION standing in for the technician's camera, rig_film.h: appliance/rig's
// CameraSimulator renders what the rig's camera sees of those files through the rig's true projectors), and the
// calibration runs from that folder. Accuracy against the rig's ground truth, next to the live run
// on the same rig (autocal's rig source, what `mogao-calibrate-sim rig` gives). Bad folders and
// manifests are refused naming the file or field, and the last good calibration stays. At 1/4
// resolution to stay fast.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <sstream>

#include <opencv2/imgcodecs.hpp>

#include "appliance/autocal/rig_bridge.h"
#include "appliance/calibration/mpcdi_reader.h"
#include "appliance/calibration/mpcdi_screen.h"
#include "appliance/calibration/mpcdi_writer.h"
#include "appliance/rig/rig_file.h"
#include "kiosk/calibrate/image_folder_source.h"
#include "kiosk/calibrate/images_job.h"
#include "kiosk/calibrate/pattern_catalogue.h"
#include "kiosk/calibrate/rig_film.h"

namespace mogao::calibrate {
namespace {

namespace fs = std::filesystem;
constexpr double kScale = 0.25;
const fs::path kStandard = MOGAO_SOURCE_DIR "/rigs/standard.toml";

std::string slurp(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

nlohmann::json read_json(const fs::path& p) { return nlohmann::json::parse(slurp(p)); }

void write_text(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

OnSiteJob standard_job(const fs::path& out) {
    OnSiteJob job;
    job.site = kStandard;
    job.scale = kScale;
    job.out = out;
    job.content = {480, 270};
    job.colour = false;
    job.transfer = CameraTransfer::linear;  // the rig's camera codes are linear
    return job;
}

// Every written file is exactly its pattern: the catalogue's signature of the codes read back.
int check_files_are_the_patterns(const fs::path& dir, const PatternCatalogue& catalogue) {
    const nlohmann::json manifest = read_json(dir / "patterns.json");
    int checked = 0;
    std::map<fs::path, cv::Mat1f> read;  // each file decoded once (every projector's black is shared)
    for (const auto& p : manifest["patterns"]) {
        std::vector<cv::Mat> signals;
        for (const auto& id : manifest["projectors"]) {
            const fs::path png = dir / p["files"][id["id"].get<std::string>()].get<std::string>();
            if (!read.contains(png)) {
                const cv::Mat1b codes = cv::imread(png.string(), cv::IMREAD_GRAYSCALE);
                EXPECT_FALSE(codes.empty()) << png;
                codes.convertTo(read[png], CV_32F, 1.0 / 255.0);
            }
            signals.push_back(read[png]);
        }
        const std::string id = p["id"];
        EXPECT_EQ(catalogue.signature(signals), catalogue.find(id)->signature) << id << ": the file is not the pattern";
        ++checked;
    }
    return checked;
}

class ImagesJobTest : public ::testing::Test {
protected:
    // One pattern set, filmed once for the whole suite (the bad-input tests point at its files).
    static void SetUpTestSuite() {
        root_ = fs::temp_directory_path() / ("mogao-calibrate-images-" + std::to_string(::getpid()));
        fs::remove_all(root_);
        rig_ = autocal::scaled_rig(rig::load_rig(kStandard), kScale, kScale);
        const OnSiteJob job = standard_job(root_ / "unused");
        catalogue_ = std::make_unique<PatternCatalogue>(site_prior(job).projectors, job.options);
        (void)write_patterns(*catalogue_, root_ / "images", kStandard.string(), kScale);
        EXPECT_EQ(check_files_are_the_patterns(root_ / "images", *catalogue_),
                  static_cast<int>(catalogue_->patterns().size()));
        // The technician's part, done by the rig (rig_film.h): each written PNG shown, filmed, saved.
        filmed_ = film_patterns(root_ / "images", rig_);
    }
    static void TearDownTestSuite() {
        fs::remove_all(root_);
        catalogue_.reset();
    }
    void SetUp() override {
        dir_ = root_ / ::testing::UnitTest::GetInstance()->current_test_info()->name();
        fs::create_directories(dir_ / "out");
        std::ofstream(dir_ / "out" / "calibration.mpcdi") << "last good";
    }
    void expect_last_good_untouched() const {
        EXPECT_EQ(slurp(dir_ / "out" / "calibration.mpcdi"), "last good");
        EXPECT_FALSE(fs::exists(dir_ / "out" / "report.json"));
        EXPECT_FALSE(fs::exists(dir_ / "out" / "calibration.models.json"));
        EXPECT_FALSE(fs::exists(dir_ / "out" / "calibration.mpcdi.last-good"));
    }
    // A folder whose captures.json is the good one changed by `edit`; its files are the good
    // captures (absolute paths) unless `edit` replaces them.
    fs::path folder_with(const std::function<void(nlohmann::json&)>& edit) const {
        nlohmann::json m = read_json(root_ / "images" / "captures.json");
        for (auto& [id, file] : m["captures"].items()) file = (root_ / "images" / file.get<std::string>()).string();
        edit(m);
        fs::create_directories(dir_ / "images");
        write_text(dir_ / "images" / "captures.json", m.dump(2));
        return dir_ / "images";
    }
    // Runs the job on `folder`; returns the error's message ("" if none).
    std::string error_of(const fs::path& folder) const {
        try {
            (void)run_from_images(standard_job(dir_ / "out"), folder);
        } catch (const std::exception& e) {
            return e.what();
        }
        return "";
    }

    static inline fs::path root_;
    static inline rig::VirtualRig rig_;
    static inline std::unique_ptr<PatternCatalogue> catalogue_;
    static inline int filmed_ = 0;
    fs::path dir_;
};

TEST_F(ImagesJobTest, PatternSetHoldsTheLiveSequenceAndWritesEachFileOnce) {
    // black, white, then per projector: white, grey, Gray bits and inverses of both axes, 8 + 8 phase shifts.
    const int column_bits = 9;  // 480 px
    const int row_bits = 9;     // 270 px
    EXPECT_EQ(static_cast<int>(catalogue_->patterns().size()), 2 + 3 * (2 + 2 * (column_bits + row_bits) + 16));
    EXPECT_EQ(filmed_, static_cast<int>(catalogue_->patterns().size()));
    const nlohmann::json m = read_json(root_ / "images" / "patterns.json");
    EXPECT_EQ(m["pattern_set"], catalogue_->set_signature());
    EXPECT_EQ(m["patterns"][3]["id"], "p0-grey");
    EXPECT_EQ(m["patterns"][6]["kind"], "gray-code");
    EXPECT_EQ(m["patterns"][6]["id"], "p0-columns-bit01");
    // Every projector's black is one file, shared.
    EXPECT_EQ(m["patterns"][0]["files"]["proj1"], m["patterns"][2]["files"]["proj1"]);
    std::size_t pngs = 0;
    for (const auto& e : fs::recursive_directory_iterator(root_ / "images" / "p0"))
        pngs += e.path().extension() == ".png";
    // black, white, own patterns (white once), grey
    EXPECT_EQ(pngs, 2u + 1u + 2u * (column_bits + row_bits) + 16u - 1u + 1u);
}

TEST_F(ImagesJobTest, CapturedImagesCalibrateAsWellAsTheLiveRun) {
    const nlohmann::json r = run_from_images(standard_job(dir_ / "out"), root_ / "images");
    const ScreenCalibration c = to_screen_calibration(read_mpcdi(dir_ / "out" / "calibration.mpcdi"));
    const autocal::GeometryError g = autocal::measure_geometry(rig_, c, 3);
    // The live run on the same rig: the calibration shows the patterns, the rig films them directly.
    autocal::RigPatternSource live_source(rig_);
    const OnSiteJob job = standard_job(dir_ / "out");
    const autocal::AutocalResult live =
        autocal::calibrate(live_source, autocal::prior_from_rig(rig_), job.content, job.options);
    MpcdiExportOptions mo;
    mo.alpha_bit_depth = job.alpha_bits;
    const autocal::GeometryError want =
        autocal::measure_geometry(rig_, to_screen_calibration(to_mpcdi(live.calibration, mo)), 3);
    std::printf(
        "captured images (standard rig, 1/4 scale, %d images): geometry mean %.3f p95 %.3f px; live: mean %.3f "
        "p95 %.3f px (projector pixels at 1/4 scale, against the rig's ground truth)\n",
        r["captures"].get<int>(), g.mean_px, g.p95_px, want.mean_px, want.p95_px);
    EXPECT_GT(g.samples, 5000);
    EXPECT_LE(g.missing, g.samples / 100);
    // The live on-site run's bound (on_site_job_test: the geometry goal, 4x as strict at 1/4 scale).
    EXPECT_LE(g.mean_px, 0.3);
    // The same images up to the camera noise's frames (the files are filmed in the set's order, the live
    // run films in its own): the same result within the noise's spread.
    EXPECT_NEAR(g.mean_px, want.mean_px, 0.02);
    EXPECT_NEAR(g.p95_px, want.p95_px, 0.05);
    // One capture read per image the live run takes (each projector's black is the set's one black).
    EXPECT_EQ(r["captures"].get<int>(), live.report.captures);
    EXPECT_EQ(r["images"]["pattern_set"], catalogue_->set_signature());
    EXPECT_FALSE(cv::imread((dir_ / "out" / "camera-white.png").string()).empty());
    EXPECT_EQ(slurp(dir_ / "out" / "calibration.mpcdi.last-good"), "last good");
}

TEST_F(ImagesJobTest, MissingCaptureFileIsRefusedNamingItAndItsPattern) {
    const fs::path folder = folder_with([](nlohmann::json& m) { m["captures"]["p1-rows-bit02"] = "gone.png"; });
    const std::string e = error_of(folder);
    EXPECT_NE(e.find("gone.png: missing (the capture of pattern 'p1-rows-bit02')"), std::string::npos) << e;
    expect_last_good_untouched();
}

TEST_F(ImagesJobTest, CaptureOfAnotherSizeIsRefusedNamingTheFileAndBothSizes) {
    const fs::path small = dir_ / "small.png";
    ASSERT_TRUE(cv::imwrite(small.string(), cv::Mat1b(100, 100, uchar{90})));
    const fs::path folder = folder_with([&](nlohmann::json& m) { m["captures"]["black"] = small.string(); });
    const std::string e = error_of(folder);
    const std::string cam =
        std::to_string(rig_.camera.resolution.width) + "x" + std::to_string(rig_.camera.resolution.height);
    EXPECT_NE(e.find("small.png: 100x100, the site file's camera is " + cam), std::string::npos) << e;
    expect_last_good_untouched();
}

TEST_F(ImagesJobTest, CapturesOfAnotherSizeAreNamedBeforeAnyIsUsed) {
    // From the files' headers, PNG and JPEG alike: not after the calibration reached the pattern.
    const fs::path png = dir_ / "late.png";
    const fs::path jpeg = dir_ / "late.jpg";
    ASSERT_TRUE(cv::imwrite(png.string(), cv::Mat1b(90, 160, uchar{90})));
    ASSERT_TRUE(cv::imwrite(jpeg.string(), cv::Mat3b(72, 128, cv::Vec3b(90, 90, 90))));
    for (const auto& [file, size] : {std::pair{png, std::string("160x90")}, std::pair{jpeg, std::string("128x72")}}) {
        CapturesManifest m = read_captures_manifest(
            folder_with([&file = file](nlohmann::json& j) { j["captures"]["p2-rows-phase-p32-s7"] = file; }));
        try {
            check_captures(m, *catalogue_, rig_.camera.resolution);
            ADD_FAILURE() << file << ": a capture of another size must be refused";
        } catch (const std::runtime_error& e) {
            EXPECT_NE(
                std::string(e.what()).find(file.filename().string() + ": " + size + ", the site file's camera is"),
                std::string::npos)
                << e.what();
        }
    }
    // The right size passes (the good folder's files).
    EXPECT_NO_THROW(check_captures(read_captures_manifest(root_ / "images"), *catalogue_, rig_.camera.resolution));
}

TEST_F(ImagesJobTest, UnreadableCaptureIsRefusedNamingTheFile) {
    const fs::path bad = dir_ / "broken.png";
    write_text(bad, "not a png");
    const fs::path folder = folder_with([&](nlohmann::json& m) { m["captures"]["black"] = bad.string(); });
    const std::string e = error_of(folder);
    EXPECT_NE(e.find("broken.png"), std::string::npos) << e;
    expect_last_good_untouched();
}

TEST_F(ImagesJobTest, ManifestThatDoesNotMatchThePatternSetIsRefusedNamingTheField) {
    EXPECT_NE(error_of(folder_with([](nlohmann::json& m) {
                  m["captures"].erase("p2-columns-phase-p32-s7");
              })).find("captures.json: field 'captures.p2-columns-phase-p32-s7' is missing: pattern"),
              std::string::npos);
    EXPECT_NE(error_of(folder_with([](nlohmann::json& m) {
                  m["captures"]["p3-white"] = "x.png";
              })).find("field 'captures.p3-white': no pattern of that id in the set"),
              std::string::npos);
    EXPECT_NE(error_of(folder_with([](nlohmann::json& m) {
                  m["pattern_set"] = "0123456789abcdef";
              })).find("field 'pattern_set' is 0123456789abcdef, the patterns of this site file"),
              std::string::npos);
    EXPECT_NE(error_of(folder_with([](nlohmann::json& m) {
                  m["phase_periods_px"] = {32, 64};
              })).find("field 'pattern_set'"),
              std::string::npos);
    EXPECT_NE(error_of(folder_with([](nlohmann::json& m) {
                  m["captures"]["black"] = 7;
              })).find("field 'captures.black' must be a file name"),
              std::string::npos);
    EXPECT_NE(error_of(folder_with([](nlohmann::json& m) { m.erase("pattern_set"); })).find("field 'pattern_set'"),
              std::string::npos);
    fs::create_directories(dir_ / "notjson");
    write_text(dir_ / "notjson" / "captures.json", "{ \"format\": ");
    EXPECT_NE(error_of(dir_ / "notjson").find("notjson/captures.json: not JSON"), std::string::npos);
    fs::create_directories(dir_ / "empty");
    EXPECT_NE(error_of(dir_ / "empty").find("empty/captures.json: cannot be read (missing"), std::string::npos);
    expect_last_good_untouched();
}

TEST_F(ImagesJobTest, PhasePeriodTheSetLacksIsNamedWithTheOptionThatAddsIt) {
    // A camera that resolves fewer Gray bits makes the live run show a longer period; from captures of
    // the default set the calibration names it instead of guessing.
    autocal::AutocalOptions o;
    o.max_gray_bits = 5;  // as if the camera resolved 5 of 9 bits: period 8 x 2^4 = 128 px
    const std::vector<cv::Mat> wanted =
        catalogue_->signals({PatternSpec::Kind::phase_shift, 1, false, -1, false, 128.0, 3, 8, o.phase_gamma});
    EXPECT_EQ(catalogue_->find(catalogue_->signature(wanted)), nullptr);
    ASSERT_TRUE(catalogue_->describe_missing_phase(wanted).has_value());
    EXPECT_EQ(*catalogue_->describe_missing_phase(wanted),
              "projector 1 'proj1' columns phase shift 3 of 8, period 128 px");
    ImageFolderSource source(*catalogue_, read_captures_manifest(root_ / "images"), rig_.camera.resolution,
                             CameraTransfer::linear);
    try {
        (void)source.show(wanted);
        FAIL() << "a pattern the set lacks must be refused";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("period 128 px, a phase period the pattern set lacks"), std::string::npos)
            << e.what();
        EXPECT_NE(std::string(e.what()).find("--phase-periods-px"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace mogao::calibrate
