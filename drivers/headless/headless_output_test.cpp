// SPDX-License-Identifier: Apache-2.0
#include "drivers/headless/headless_output.h"

#include <gtest/gtest.h>

#include <optional>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <unistd.h>

#include "common/png_io.h"
#include "drivers/egl/egl_test_support.h"
#include "drivers/egl/test_pattern.h"

namespace mogao {
namespace {

using mogao::testing::skip_or_fail_without_egl;

int max_abs_diff(const Rgb8Image& a, const Rgb8Image& b) {
    if (!(a.size == b.size)) return 256;
    int d = 0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) d = std::max(d, std::abs(int{a.pixels[i]} - int{b.pixels[i]}));
    return d;
}

std::filesystem::path fresh_dir(const std::string& name) {
    const auto dir = std::filesystem::temp_directory_path() / ("mogao-" + name + "-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

std::unique_ptr<HeadlessOutputBackend> make_backend(HeadlessOptions options) {
    auto backend = HeadlessOutputBackend::create(std::move(options));
    if (!backend) {
        if (backend.code() == ENODEV) skip_or_fail_without_egl(backend.error().message);
        else ADD_FAILURE() << backend.error().message;
        return nullptr;
    }
    return std::move(backend).value();
}

TEST(HeadlessOutputBackend, PresentsEachOutputAndWritesPngs) {
    const auto dir = fresh_dir("headless");
    auto backend = make_backend({{{64, 48}, {32, 16}}, dir});
    if (!backend) return;
    ASSERT_EQ(backend->outputs().size(), 2u);
    EXPECT_EQ(backend->outputs()[1].name, "headless-1");
    EXPECT_EQ(backend->outputs()[1].size, (ImageSize{32, 16}));
    EXPECT_EQ(backend->event_fd(), -1);

    WarpBlendRenderer& renderer = backend->renderer();
    std::vector<std::size_t> projector;
    for (const auto& out : backend->outputs()) {
        auto p = renderer.add_projector(identity_calibration(out.name, out.size));
        ASSERT_TRUE(p) << p.error().message;
        projector.push_back(*p);
    }
    for (int frame = 0; frame < 2; ++frame) {
        for (std::size_t i = 0; i < backend->outputs().size(); ++i) {
            const Rgb8Image content = make_test_pattern(backend->outputs()[i].size);
            ASSERT_TRUE(renderer.set_content(content).ok());
            ASSERT_TRUE(backend->ready(i));
            ASSERT_TRUE(backend->begin_frame(i).ok());
            ASSERT_TRUE(renderer.draw(projector[i]).ok());
            const Status s = backend->present(i);
            ASSERT_TRUE(s.ok()) << s.error().message;
            EXPECT_LE(max_abs_diff(backend->last_frame(i), content), 1);
        }
    }
    auto events = backend->dispatch_events();
    ASSERT_TRUE(events);
    EXPECT_TRUE(events->empty());
    EXPECT_EQ(backend->frame_count(0), 2u);
    const auto png = dir / "headless-1-000001.png";
    ASSERT_TRUE(std::filesystem::exists(png));
    EXPECT_EQ(max_abs_diff(read_png(png), backend->last_frame(1)), 0);
    std::filesystem::remove_all(dir);
}

TEST(HeadlessOutputBackend, BeginFrameClearsToBlack) {
    auto backend = make_backend({{{8, 8}}, {}});
    if (!backend) return;
    ASSERT_TRUE(backend->begin_frame(0).ok());
    ASSERT_TRUE(backend->present(0).ok());
    EXPECT_EQ(max_abs_diff(backend->last_frame(0), Rgb8Image({8, 8}, 0)), 0);
}

// A round (drivers/output.h): every output staged, then one commit that stamps them all with the
// same presentation time, later than the previous round's.
TEST(HeadlessOutputBackend, RoundStampsEveryStagedOutputWithOneTime) {
    auto backend = make_backend({{{8, 8}, {6, 4}}, {}});
    if (!backend) return;
    EXPECT_FALSE(backend->presented_ns(0).has_value()) << "nothing presented yet";
    std::optional<std::int64_t> previous;
    for (int round = 0; round < 2; ++round) {
        for (std::size_t i = 0; i < 2; ++i) {
            ASSERT_TRUE(backend->begin_frame(i).ok());
            ASSERT_TRUE(backend->stage(i).ok());
        }
        ASSERT_TRUE(backend->commit_round().ok());
        const auto t0 = backend->presented_ns(0);
        ASSERT_TRUE(t0.has_value());
        EXPECT_EQ(backend->presented_ns(1), t0) << "one round, one time";
        if (previous) {
            EXPECT_GE(*t0, *previous);
        }
        previous = t0;
    }
    EXPECT_EQ(backend->frame_count(1), 2u);
    EXPECT_EQ(backend->stage(0).code(), EINVAL) << "stage without begin_frame";
    EXPECT_FALSE(backend->presented_ns(5).has_value());
}

TEST(HeadlessOutputBackend, ReportsMisuseAndFileErrors) {
    EXPECT_EQ(HeadlessOutputBackend::create({}).code(), EINVAL);
    auto empty = HeadlessOutputBackend::create({{{0, 4}}, {}});
    if (empty.code() == ENODEV) return skip_or_fail_without_egl(empty.error().message);
    EXPECT_EQ(empty.code(), EINVAL);

    auto backend = make_backend({{{8, 8}}, "/nonexistent/mogao"});
    if (!backend) return;
    EXPECT_EQ(backend->present(0).code(), EINVAL);  // no begin_frame
    EXPECT_EQ(backend->begin_frame(3).code(), EINVAL);
    EXPECT_FALSE(backend->ready(3));
    ASSERT_TRUE(backend->begin_frame(0).ok());
    const Status s = backend->present(0);
    EXPECT_EQ(s.code(), EIO);
    EXPECT_EQ(backend->last_frame(0).size, (ImageSize{8, 8}));  // the frame is kept anyway
}

}  // namespace
}  // namespace mogao
