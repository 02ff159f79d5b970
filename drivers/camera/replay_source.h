// SPDX-License-Identifier: Apache-2.0
// ReplaySource: a folder of images played back as a camera, for tests, demos and the benchmark.
//
// Files: every *.png, *.pgm, *.jpg, *.jpeg (any case) directly in the folder, in byte-wise name
// order (write names zero-padded: frame-00000.png). Each is read by read_gray_image (image_file.h:
// PNG, binary PGM, JPEG; colour converted to grey as documented there). Images may differ in size.
//
// Timestamps: if the folder has `timestamps.txt`, its lines are the frames' timestamps in ns, one
// integer per line in file order, strictly increasing, as many lines as images (the hand-held
// sequence generator writes one). Otherwise frame i is stamped i * 1e9 / fps. With `loop`, each
// pass continues after the last stamp plus one frame period (the mean period of timestamps.txt).
//
// Playback is as fast as next_frame() is called; pacing to real time is the caller's business.
// Images are decoded on demand, so a long sequence costs no memory up front, and
// skip_frames_due_by() drops the frames a slow caller would discard without decoding them.
//
// Errors (common/result.h): open() gives ENOENT for a missing folder or one without images,
// EINVAL for a bad config or timestamps.txt (naming the file, the line and the rule);
// next_frame() gives EBADMSG naming the file that cannot be decoded, ENODATA after the last frame.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "drivers/camera/frame_source.h"

namespace mogao {

struct ReplayConfig {
    std::filesystem::path folder;
    double frames_per_second = 30.0;  // (0, 1000]; used when there is no timestamps.txt
    bool loop = false;                // start again after the last frame instead of ENODATA
};

class ReplaySource final : public FrameSource {
public:
    [[nodiscard]] static Result<std::unique_ptr<ReplaySource>> open(const ReplayConfig& config);

    [[nodiscard]] Result<CameraFrame> next_frame() override;
    [[nodiscard]] std::optional<std::int64_t> next_capture_time_ns() const override;
    std::uint64_t skip_frames_due_by(std::int64_t now_ns) override;
    [[nodiscard]] std::string description() const override;

    [[nodiscard]] const std::vector<std::filesystem::path>& files() const { return files_; }
    [[nodiscard]] const std::vector<std::int64_t>& timestamps_ns() const { return stamps_; }

private:
    ReplaySource() = default;
    // Timestamp of file `index` on loop pass `pass`.
    [[nodiscard]] std::int64_t stamp_ns(std::size_t index, std::uint64_t pass) const {
        return stamps_[index] + static_cast<std::int64_t>(pass) * pass_duration_ns_;
    }

    ReplayConfig config_;
    std::vector<std::filesystem::path> files_;
    std::vector<std::int64_t> stamps_;   // one per file
    std::int64_t pass_duration_ns_ = 0;  // added to the stamps on each loop pass
    std::size_t next_ = 0;
    std::uint64_t pass_ = 0;
};

}  // namespace mogao
