// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/policy_gate.h"

#include <memory>
#include <string>

#include <gtest/gtest.h>
#include <spdlog/sinks/ringbuffer_sink.h>
#include <spdlog/spdlog.h>

namespace mogao {
namespace {

// The farm's journal lines while a test runs.
class JournalLines {
public:
    JournalLines() : sink_(std::make_shared<spdlog::sinks::ringbuffer_sink_mt>(4096)) {
        spdlog::default_logger()->sinks().push_back(sink_);
    }
    ~JournalLines() { spdlog::default_logger()->sinks().pop_back(); }
    JournalLines(const JournalLines&) = delete;
    JournalLines& operator=(const JournalLines&) = delete;
    [[nodiscard]] int containing(const std::string& text) const {
        int n = 0;
        for (const std::string& line : sink_->last_formatted())
            if (line.find(text) != std::string::npos) ++n;
        return n;
    }

private:
    std::shared_ptr<spdlog::sinks::ringbuffer_sink_mt> sink_;
};

// A visitor pressing against the visitable area's edge for ten minutes at 60 requests a second: the
// eye (and so the change's text) differs with every request. The journal gets one line a minute,
// not one per request (before: 36000 lines, about 400 KiB an hour in the soak).
TEST(PolicyGateLog, AVisitorPressingAgainstTheAreasEdgeLogsAboutOneLineAMinute) {
    Scene scene;
    scene.viewer.visitable = VisitableArea{{-4.0, -2.0}, {4.0, 7.0}, {0.0, 0.0}, 0.0, 1.2, 2.0};
    PolicyGate gate(scene, RequestPolicy{}, ViewPolicies{});
    JournalLines journal;
    ViewRequest r;
    r.size = {960, 540};
    r.session = 7;
    const int requests = 60 * 600;
    for (int i = 0; i < requests; ++i) {
        r.pose.eye = {4.5 + 0.001 * (i % 100), 1.6, 0.0001 * (i % 50000)};  // beyond x = 4, sliding along it
        (void)gate.apply(r, "museum-1", 1000.0 + i / 60.0);
    }
    EXPECT_EQ(gate.changed(), static_cast<std::uint64_t>(requests)) << "the metrics count every change";
    EXPECT_EQ(journal.containing("view outside its view policy"), 10);
    EXPECT_EQ(journal.containing("more since the last line)"), 9);
    // Another session's first change is written at once.
    r.session = 8;
    (void)gate.apply(r, "museum-2", 1000.0 + requests / 60.0);
    EXPECT_EQ(journal.containing("session 8 (museum-2): view outside its view policy"), 1);
}

}  // namespace
}  // namespace mogao
