// SPDX-License-Identifier: Apache-2.0
#include "drivers/camera/v4l2_capture.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <time.h>

#include <algorithm>
#include <cstring>

#include "drivers/camera/pixel_format.h"

namespace mogao {
namespace {

// ioctl that retries when a signal interrupts it (V4L2 uAPI "xioctl").
int xioctl(int fd, unsigned long request, void* arg) {
    int r = 0;
    do {
        r = ::ioctl(fd, request, arg);
    } while (r == -1 && errno == EINTR);
    return r;
}

std::uint32_t fourcc_of(CaptureFormat format) {
    switch (format) {
        case CaptureFormat::grey:
            return V4L2_PIX_FMT_GREY;
        case CaptureFormat::yuyv:
            return V4L2_PIX_FMT_YUYV;
        case CaptureFormat::mjpeg:
            return V4L2_PIX_FMT_MJPEG;
        case CaptureFormat::image_file:
            break;
    }
    return 0;
}

std::int64_t monotonic_now_ns() {
    timespec ts{};
    ::clock_gettime(CLOCK_MONOTONIC, &ts);
    return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

Status check_config(const V4l2Config& c) {
    const auto bad = [](const std::string& what) { return make_error(EINVAL, "V4l2Config: " + what); };
    if (c.device.empty()) return bad("device is empty");
    if (c.width < 1 || c.width > kMaxCaptureDimension || c.height < 1 || c.height > kMaxCaptureDimension) {
        return bad("width x height " + std::to_string(c.width) + "x" + std::to_string(c.height) + " outside [1, " +
                   std::to_string(kMaxCaptureDimension) + "]");
    }
    if (c.formats.empty()) return bad("formats is empty");
    for (CaptureFormat f : c.formats) {
        if (fourcc_of(f) == 0) return bad("formats: only GREY, YUYV and MJPG can be captured");
    }
    if (c.buffer_count < 2 || c.buffer_count > 4) {
        return bad("buffer_count " + std::to_string(c.buffer_count) + " outside [2, 4]");
    }
    if (c.frames_per_second < 0 || c.frames_per_second > 1000) {
        return bad("frames_per_second " + std::to_string(c.frames_per_second) + " outside [0, 1000]");
    }
    if (c.timeout_ms < 1 || c.timeout_ms > 60000) {
        return bad("timeout_ms " + std::to_string(c.timeout_ms) + " outside [1, 60000]");
    }
    return {};
}

}  // namespace

Result<std::unique_ptr<V4l2Capture>> V4l2Capture::open(const V4l2Config& config) {
    if (Status s = check_config(config); !s) return s.error();
    std::unique_ptr<V4l2Capture> cam(new V4l2Capture());
    cam->device_ = config.device;
    cam->timeout_ms_ = config.timeout_ms;
    cam->fd_ = UniqueFd(::open(config.device.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC));
    if (!cam->fd_.valid()) return errno_error("open " + config.device);

    v4l2_capability cap{};
    if (xioctl(cam->fd_.get(), VIDIOC_QUERYCAP, &cap) == -1) {
        const int code = errno;
        return make_error(code == ENOTTY ? ENOTTY : code,
                          config.device + ": VIDIOC_QUERYCAP: " + std::strerror(code) + " (not a V4L2 device?)");
    }
    cam->driver_ = reinterpret_cast<const char*>(cap.driver);
    // device_caps describes this node; capabilities the whole physical device.
    const std::uint32_t caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) != 0 ? cap.device_caps : cap.capabilities;
    if ((caps & V4L2_CAP_VIDEO_CAPTURE) == 0) {
        return make_error(ENODEV, config.device + " (" + cam->driver_ + "): not a single-planar video capture node");
    }
    if ((caps & V4L2_CAP_STREAMING) == 0) {
        return make_error(ENODEV, config.device + " (" + cam->driver_ + "): no streaming I/O");
    }
    if (Status s = cam->negotiate_format(config); !s) return s.error();
    if (Status s = cam->start_streaming(config); !s) return s.error();
    return cam;
}

Status V4l2Capture::negotiate_format(const V4l2Config& config) {
    std::vector<std::uint32_t> offered;
    for (std::uint32_t i = 0;; ++i) {
        v4l2_fmtdesc desc{};
        desc.index = i;
        desc.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        if (xioctl(fd_.get(), VIDIOC_ENUM_FMT, &desc) == -1) break;  // EINVAL ends the list
        offered.push_back(desc.pixelformat);
    }
    const auto wanted = std::find_if(config.formats.begin(), config.formats.end(), [&](CaptureFormat f) {
        return std::find(offered.begin(), offered.end(), fourcc_of(f)) != offered.end();
    });
    if (wanted == config.formats.end()) {
        std::string list;
        for (std::uint32_t f : offered) list += (list.empty() ? "" : ", ") + fourcc_name(f);
        return make_error(ENOTSUP, device_ + ": none of the wanted formats (GREY/YUYV/MJPG) is offered; device has: " +
                                       (list.empty() ? std::string("none") : list));
    }
    v4l2_format fmt{};
    fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    fmt.fmt.pix.width = static_cast<std::uint32_t>(config.width);
    fmt.fmt.pix.height = static_cast<std::uint32_t>(config.height);
    fmt.fmt.pix.pixelformat = fourcc_of(*wanted);
    fmt.fmt.pix.field = V4L2_FIELD_NONE;
    if (xioctl(fd_.get(), VIDIOC_S_FMT, &fmt) == -1) return errno_error(device_ + ": VIDIOC_S_FMT");
    if (fmt.fmt.pix.pixelformat != fourcc_of(*wanted)) {
        return make_error(ENOTSUP, device_ + ": VIDIOC_S_FMT: asked " + fourcc_name(fourcc_of(*wanted)) + ", got " +
                                       fourcc_name(fmt.fmt.pix.pixelformat));
    }
    if (fmt.fmt.pix.field != V4L2_FIELD_NONE && fmt.fmt.pix.field != V4L2_FIELD_ANY) {
        return make_error(ENOTSUP, device_ + ": interlaced capture (field " + std::to_string(fmt.fmt.pix.field) +
                                       ") is not supported");
    }
    format_ = *wanted;
    width_ = static_cast<int>(fmt.fmt.pix.width);
    height_ = static_cast<int>(fmt.fmt.pix.height);
    bytes_per_line_ = static_cast<int>(fmt.fmt.pix.bytesperline);
    if (width_ < 1 || height_ < 1 || width_ > kMaxCaptureDimension || height_ > kMaxCaptureDimension) {
        return make_error(EINVAL, device_ + ": driver chose size " + std::to_string(width_) + "x" +
                                      std::to_string(height_) + ", outside [1, " +
                                      std::to_string(kMaxCaptureDimension) + "]");
    }
    if (format_ == CaptureFormat::mjpeg) {
        auto decoder = MjpegDecoder::create();
        if (!decoder) return decoder.error();
        mjpeg_ = std::make_unique<MjpegDecoder>(std::move(decoder).value());
    }
    if (config.frames_per_second > 0) {
        // Best effort: many drivers ignore or round the rate; the timestamps are what counts.
        v4l2_streamparm parm{};
        parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        parm.parm.capture.timeperframe.numerator = 1;
        parm.parm.capture.timeperframe.denominator = static_cast<std::uint32_t>(config.frames_per_second);
        (void)xioctl(fd_.get(), VIDIOC_S_PARM, &parm);
    }
    return {};
}

Status V4l2Capture::start_streaming(const V4l2Config& config) {
    v4l2_requestbuffers req{};
    req.count = static_cast<std::uint32_t>(config.buffer_count);
    req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    req.memory = V4L2_MEMORY_MMAP;
    if (xioctl(fd_.get(), VIDIOC_REQBUFS, &req) == -1) return errno_error(device_ + ": VIDIOC_REQBUFS (mmap)");
    if (req.count < 2) {
        return make_error(ENOMEM, device_ + ": VIDIOC_REQBUFS granted " + std::to_string(req.count) +
                                      " buffer(s), at least 2 are needed");
    }
    for (std::uint32_t i = 0; i < req.count; ++i) {
        v4l2_buffer buf{};
        buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        buf.memory = V4L2_MEMORY_MMAP;
        buf.index = i;
        if (xioctl(fd_.get(), VIDIOC_QUERYBUF, &buf) == -1) {
            return errno_error(device_ + ": VIDIOC_QUERYBUF " + std::to_string(i));
        }
        auto mapping = MappedBuffer::map(fd_.get(), buf.length, static_cast<off_t>(buf.m.offset));
        if (!mapping) return with_context(mapping.error(), device_ + ": buffer " + std::to_string(i));
        buffers_.push_back(std::move(mapping).value());
        if (Status s = requeue(i); !s) return s;
    }
    v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (xioctl(fd_.get(), VIDIOC_STREAMON, &type) == -1) return errno_error(device_ + ": VIDIOC_STREAMON");
    streaming_ = true;
    return {};
}

V4l2Capture::~V4l2Capture() {
    if (streaming_) {
        v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        (void)xioctl(fd_.get(), VIDIOC_STREAMOFF, &type);  // nothing to do on failure: the fd closes next
    }
}

Status V4l2Capture::requeue(std::uint32_t index) {
    v4l2_buffer buf{};
    buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buf.memory = V4L2_MEMORY_MMAP;
    buf.index = index;
    if (xioctl(fd_.get(), VIDIOC_QBUF, &buf) == -1)
        return errno_error(device_ + ": VIDIOC_QBUF " + std::to_string(index));
    return {};
}

Status V4l2Capture::convert(std::uint32_t index, std::uint32_t bytes_used, GrayImage& out) {
    std::span<const std::uint8_t> bytes = buffers_[index].bytes();
    // bytesused bounds a compressed frame; a driver that leaves it 0 for a raw format gets the
    // whole buffer (the layout checks still demand the full image).
    if (bytes_used != 0) bytes = bytes.first(std::min<std::size_t>(bytes.size(), bytes_used));
    Status s;
    switch (format_) {
        case CaptureFormat::grey:
            s = grey_from_grey(bytes, width_, height_, bytes_per_line_, out);
            break;
        case CaptureFormat::yuyv:
            s = grey_from_yuyv(bytes, width_, height_, bytes_per_line_, out);
            break;
        case CaptureFormat::mjpeg:
            s = mjpeg_->decode_grey(bytes, out, width_, height_);
            break;
        case CaptureFormat::image_file:
            s = make_error(EINVAL, "image_file is not a capture format");
            break;
    }
    if (!s) return make_error(EBADMSG, device_ + ": " + s.error().message);
    return {};
}

Result<CameraFrame> V4l2Capture::next_frame() {
    const std::int64_t deadline = monotonic_now_ns() + std::int64_t{timeout_ms_} * 1'000'000;
    for (;;) {
        const std::int64_t left_ms = (deadline - monotonic_now_ns()) / 1'000'000;
        if (left_ms <= 0)
            return make_error(ETIMEDOUT, device_ + ": no frame for " + std::to_string(timeout_ms_) + " ms");
        pollfd pfd{fd_.get(), POLLIN, 0};
        const int ready = ::poll(&pfd, 1, static_cast<int>(left_ms));
        if (ready == -1) {
            if (errno == EINTR) continue;
            return errno_error(device_ + ": poll");
        }
        if (ready == 0) continue;  // the loop reports the timeout
        if ((pfd.revents & POLLERR) != 0)
            return make_error(ENODEV, device_ + ": poll reported an error (device gone?)");

        // Drain every ready buffer; keep the newest, give the older ones straight back.
        v4l2_buffer newest{};
        bool have = false;
        std::uint32_t skipped = 0;
        for (;;) {
            v4l2_buffer buf{};
            buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
            buf.memory = V4L2_MEMORY_MMAP;
            if (xioctl(fd_.get(), VIDIOC_DQBUF, &buf) == -1) {
                if (errno == EAGAIN) break;
                const Error e = errno_error(device_ + ": VIDIOC_DQBUF");
                if (have) (void)requeue(newest.index);
                return e;
            }
            if (buf.index >= buffers_.size()) return make_error(EIO, device_ + ": VIDIOC_DQBUF returned a bad index");
            if ((buf.flags & V4L2_BUF_FLAG_ERROR) != 0) {  // a damaged frame: drop it
                if (Status s = requeue(buf.index); !s) return s.error();
                ++skipped;
                continue;
            }
            if (have) {
                if (Status s = requeue(newest.index); !s) return s.error();
                ++skipped;
            }
            newest = buf;
            have = true;
        }
        if (!have) continue;  // only damaged frames were ready: wait for the next

        CameraFrame frame;
        frame.format = format_;
        frame.sequence = newest.sequence;
        frame.skipped = skipped;
        if ((newest.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) == V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC) {
            frame.timestamp_ns =
                std::int64_t{newest.timestamp.tv_sec} * 1'000'000'000 + std::int64_t{newest.timestamp.tv_usec} * 1000;
            frame.clock = TimestampSource::kernel_monotonic;
        } else {
            frame.timestamp_ns = monotonic_now_ns();
            frame.clock = TimestampSource::dequeue_monotonic;
        }
        const Status converted = convert(newest.index, newest.bytesused, frame.image);
        if (Status s = requeue(newest.index); !s) return s.error();
        if (!converted) return converted.error();
        return frame;
    }
}

std::string V4l2Capture::description() const {
    return device_ + " (" + driver_ + ") " + std::to_string(width_) + "x" + std::to_string(height_) + " " +
           pixel_format_name(format_) + ", " + std::to_string(buffers_.size()) + " mmap buffers";
}

}  // namespace mogao
