// SPDX-License-Identifier: Apache-2.0
// HeadlessRecorder: what the headless kiosk leaves behind for people and tests to look at.
//
// * Every k-th display round (a round = one show or repaint that presented the outputs), and every
//   round the caller forces (a frame held unchanged: KioskDisplay::repaint), each output's pixels as
//   <dir>/<output>-<round, 6 digits>-req<request id>.png (request id 0 = the kiosk's connecting screen), written
//   atomically (common/png_io.h). The pixels are copied on the calling (display) thread and encoded on the recorder's
//   own thread: a PNG encode of three projector outputs costs as much as drawing them on a software rasteriser, and it
//   is no part of presenting. At most kMaxQueuedRounds rounds wait to be encoded; a round beyond that waits for the
//   writer (no PNG is ever dropped). Destruction writes what is queued, then joins.
// * At exit, <dir>/screen-composite.png: the light on the cylindrical screen computed by the CPU
//   reference composite_on_screen (appliance/warp/composite.h) from the last frame of every
//   output, encoded back to sRGB. It is content-sized and should look like the content frame:
//   visible seams or a wrong brightness in the overlaps mean the calibration or the GL path is off.
//
// Errors: write_composite throws EncodeError or std::invalid_argument naming the file; the kiosk
// logs it and carries on (a full disk must not stop the show). write_round's files are written on
// the recorder's thread, which logs a failure as a warning naming the file and carries on.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>
#include <vector>

#include "common/projector_calibration.h"
#include "drivers/headless/headless_output.h"

namespace mogao {

class HeadlessRecorder {
public:
    // `dir` is created if missing (std::filesystem_error when it cannot be). every >= 1.
    HeadlessRecorder(const HeadlessOutputBackend& backend, std::filesystem::path dir, int every);

    // After display round `round` (counted from 1) showed request `request_id`: queues the PNGs
    // when round % every == 0 or `forced`. Returns the number of files queued.
    std::size_t write_round(std::uint64_t round, std::uint64_t request_id, bool forced = false);
    [[nodiscard]] int every() const { return every_; }
    // Blocks until every queued PNG is on disk (or failed and was logged).
    void flush();

    // The composited screen from the outputs' last frames; projector_of[i] is output i's projector
    // in `screen` (ScreenPresenter::projector_of). Outputs without a frame or projector add no light.
    void write_composite(const ScreenCalibration& screen, const std::vector<std::optional<std::size_t>>& projector_of,
                         const std::filesystem::path& file) const;

    [[nodiscard]] const std::filesystem::path& dir() const { return dir_; }

    static constexpr std::size_t kMaxQueuedRounds = 2;

private:
    // The encoding thread and its queue; behind a pointer so that the recorder stays movable.
    class Writer {
    public:
        Writer();
        ~Writer();  // writes what is queued, then joins
        Writer(const Writer&) = delete;
        Writer& operator=(const Writer&) = delete;
        void push(std::vector<std::pair<std::filesystem::path, Rgb8Image>> round);  // waits while full
        void flush();

    private:
        void run();
        std::mutex mutex_;
        std::condition_variable changed_;
        std::deque<std::vector<std::pair<std::filesystem::path, Rgb8Image>>> queue_;
        bool busy_ = false;  // a round taken off the queue is being written
        bool stop_ = false;
        std::thread thread_;  // last: started once the members above exist
    };

    const HeadlessOutputBackend* backend_;
    std::filesystem::path dir_;
    int every_;
    std::unique_ptr<Writer> writer_;
};

}  // namespace mogao
