// SPDX-License-Identifier: Apache-2.0
#include "drivers/camera/replay_source.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <system_error>

#include "drivers/camera/image_file.h"
#include "drivers/camera/pixel_format.h"

namespace mogao {
namespace {

bool is_image(const std::filesystem::path& p) {
    std::string ext = p.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext == ".png" || ext == ".pgm" || ext == ".jpg" || ext == ".jpeg";
}

// timestamps.txt: one strictly increasing integer (ns) per line, `count` lines.
Result<std::vector<std::int64_t>> read_timestamps(const std::filesystem::path& path, std::size_t count) {
    std::ifstream in(path);
    if (!in) return errno_error("read " + path.string());
    std::vector<std::int64_t> stamps;
    std::string line;
    while (std::getline(in, line)) {
        if (line.empty()) continue;
        const std::string where = path.string() + ":" + std::to_string(stamps.size() + 1);
        std::size_t used = 0;
        long long value = 0;
        try {
            value = std::stoll(line, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used == 0 || line.find_first_not_of(" \t\r", used) != std::string::npos) {
            return make_error(EINVAL, where + ": '" + line + "' is not an integer timestamp in ns");
        }
        if (!stamps.empty() && value <= stamps.back()) {
            return make_error(EINVAL, where + ": timestamp " + std::to_string(value) + " does not increase (previous " +
                                          std::to_string(stamps.back()) + ")");
        }
        stamps.push_back(value);
    }
    if (stamps.size() != count) {
        return make_error(EINVAL, path.string() + ": " + std::to_string(stamps.size()) + " timestamps for " +
                                      std::to_string(count) + " images (need one per image)");
    }
    return stamps;
}

}  // namespace

Result<std::unique_ptr<ReplaySource>> ReplaySource::open(const ReplayConfig& config) {
    if (!(config.frames_per_second > 0.0 && config.frames_per_second <= 1000.0)) {
        return make_error(EINVAL, "ReplayConfig: frames_per_second " + std::to_string(config.frames_per_second) +
                                      " outside (0, 1000]");
    }
    std::error_code ec;
    if (!std::filesystem::is_directory(config.folder, ec)) {
        return make_error(ENOENT, "replay folder " + config.folder.string() + ": not a directory");
    }
    std::unique_ptr<ReplaySource> src(new ReplaySource());
    src->config_ = config;
    // increment(ec) rather than a range-for: drivers/ code must not throw filesystem_error.
    for (std::filesystem::directory_iterator it(config.folder, ec), end; !ec && it != end; it.increment(ec)) {
        std::error_code type_ec;
        if (it->is_regular_file(type_ec) && is_image(it->path())) src->files_.push_back(it->path());
    }
    if (ec) return make_error(ec.value(), "replay folder " + config.folder.string() + ": " + ec.message());
    if (src->files_.empty()) {
        return make_error(ENOENT, "replay folder " + config.folder.string() + ": no .png/.pgm/.jpg/.jpeg images");
    }
    std::sort(src->files_.begin(), src->files_.end(),
              [](const auto& a, const auto& b) { return a.filename().string() < b.filename().string(); });

    const auto stamps_file = config.folder / "timestamps.txt";
    const auto n = src->files_.size();
    if (std::filesystem::exists(stamps_file, ec)) {
        auto stamps = read_timestamps(stamps_file, n);
        if (!stamps) return stamps.error();
        src->stamps_ = std::move(stamps).value();
        const std::int64_t span = src->stamps_.back() - src->stamps_.front();
        src->pass_duration_ns_ = n > 1 ? span + span / static_cast<std::int64_t>(n - 1) : 1;
    } else {
        const double period_ns = 1e9 / config.frames_per_second;
        for (std::size_t i = 0; i < n; ++i) src->stamps_.push_back(std::llround(static_cast<double>(i) * period_ns));
        src->pass_duration_ns_ = std::llround(static_cast<double>(n) * period_ns);
    }
    return src;
}

Result<CameraFrame> ReplaySource::next_frame() {
    if (next_ == files_.size()) {
        if (!config_.loop) return make_error(ENODATA, "replay " + config_.folder.string() + ": end of sequence");
        next_ = 0;
        ++pass_;
    }
    const std::size_t i = next_++;
    auto image = read_gray_image(files_[i]);
    if (!image) return make_error(EBADMSG, image.error().message);
    CameraFrame frame;
    frame.image = std::move(image).value();
    frame.timestamp_ns = stamps_[i] + static_cast<std::int64_t>(pass_) * pass_duration_ns_;
    frame.clock = TimestampSource::replay;
    frame.sequence = pass_ * files_.size() + i;
    frame.format = CaptureFormat::image_file;
    return frame;
}

std::optional<std::int64_t> ReplaySource::next_capture_time_ns() const {
    if (next_ < files_.size()) return stamps_[next_] + static_cast<std::int64_t>(pass_) * pass_duration_ns_;
    if (!config_.loop) return std::nullopt;
    return stamps_.front() + static_cast<std::int64_t>(pass_ + 1) * pass_duration_ns_;  // the next pass's first
}

std::uint64_t ReplaySource::skip_frames_due_by(std::int64_t now_ns) {
    const std::size_t n = files_.size();
    std::uint64_t skipped = 0;
    for (;;) {
        // (i, pass): the frame next_frame() would return; (j, pass_j): its successor.
        std::size_t i = next_;
        std::uint64_t pass = pass_;
        if (i == n) {
            if (!config_.loop) break;
            i = 0;
            ++pass;
        }
        std::size_t j = i + 1;
        std::uint64_t pass_j = pass;
        if (j == n) {
            if (!config_.loop) break;  // the last frame has no successor: it is never stale
            j = 0;
            ++pass_j;
        }
        if (stamp_ns(j, pass_j) > now_ns) break;
        // Far behind while looping: whole passes at once (no loop over millions of frames).
        if (config_.loop && pass_duration_ns_ > 0 && stamp_ns(j, pass_j) + pass_duration_ns_ <= now_ns) {
            const auto passes = static_cast<std::uint64_t>((now_ns - stamp_ns(j, pass_j)) / pass_duration_ns_);
            pass_j += passes;
            skipped += passes * n;
        }
        next_ = j;
        pass_ = pass_j;
        ++skipped;
    }
    return skipped;
}

std::string ReplaySource::description() const {
    return "replay " + config_.folder.string() + " (" + std::to_string(files_.size()) + " images" +
           (config_.loop ? ", looping)" : ")");
}

}  // namespace mogao
