// SPDX-License-Identifier: Apache-2.0
#include "drivers/camera/v4l2_capture.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <time.h>

#include <algorithm>
#include <cstring>
#include <optional>

#include "drivers/camera/pixel_format.h"
#include "drivers/camera/v4l2_ioctl.h"

namespace mogao {
namespace {

// The one-buffer fourcc of a format (0 for image_file).
std::uint32_t fourcc_of(CaptureFormat format) {
    switch (format) {
        case CaptureFormat::grey:
            return V4L2_PIX_FMT_GREY;
        case CaptureFormat::yuyv:
            return V4L2_PIX_FMT_YUYV;
        case CaptureFormat::mjpeg:
            return V4L2_PIX_FMT_MJPEG;
        case CaptureFormat::nv12:
            return V4L2_PIX_FMT_NV12;
        case CaptureFormat::nv21:
            return V4L2_PIX_FMT_NV21;
        case CaptureFormat::yuv420:
            return V4L2_PIX_FMT_YUV420;
        case CaptureFormat::yvu420:
            return V4L2_PIX_FMT_YVU420;
        case CaptureFormat::rgb24:
            return V4L2_PIX_FMT_RGB24;
        case CaptureFormat::bgr24:
            return V4L2_PIX_FMT_BGR24;
        case CaptureFormat::image_file:
            break;
    }
    return 0;
}

// The multi-plane (one buffer per plane) fourcc of a 4:2:0 format, else 0.
std::uint32_t multiplane_fourcc_of(CaptureFormat format) {
    switch (format) {
        case CaptureFormat::nv12:
            return V4L2_PIX_FMT_NV12M;
        case CaptureFormat::nv21:
            return V4L2_PIX_FMT_NV21M;
        case CaptureFormat::yuv420:
            return V4L2_PIX_FMT_YUV420M;
        case CaptureFormat::yvu420:
            return V4L2_PIX_FMT_YVU420M;
        default:
            return 0;
    }
}

bool offered_has(const std::vector<std::uint32_t>& offered, std::uint32_t fourcc) {
    return fourcc != 0 && std::find(offered.begin(), offered.end(), fourcc) != offered.end();
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
        if (fourcc_of(f) == 0) return bad("formats: image_file is not a capture format");
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
    if ((caps & (V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_VIDEO_CAPTURE_MPLANE)) == 0) {
        return make_error(ENODEV, config.device + " (" + cam->driver_ + "): not a video capture node");
    }
    cam->multiplanar_ = (caps & V4L2_CAP_VIDEO_CAPTURE) == 0;
    cam->buf_type_ = cam->multiplanar_ ? V4L2_BUF_TYPE_VIDEO_CAPTURE_MPLANE : V4L2_BUF_TYPE_VIDEO_CAPTURE;
    cam->colour_ = config.colour;
    if ((caps & V4L2_CAP_STREAMING) == 0) {
        return make_error(ENODEV, config.device + " (" + cam->driver_ + "): no streaming I/O");
    }
    if (Status s = cam->negotiate_format(config); !s) return s.error();
    if (Status s = apply_v4l2_controls(cam->fd_.get(), cam->device_, config.controls, &cam->skipped_controls_); !s)
        return s.error();
    if (Status s = cam->start_streaming(config); !s) return s.error();
    return cam;
}

namespace {

// The wanted format the device offers (first in preference), and the fourcc to ask for: on a
// multi-planar node the multi-plane variant when offered.
struct Choice {
    CaptureFormat format = CaptureFormat::grey;
    std::uint32_t fourcc = 0;
};

std::optional<Choice> choose_format(const V4l2Config& config, const std::vector<std::uint32_t>& offered,
                                    bool multiplanar) {
    for (CaptureFormat f : config.formats) {
        if (config.colour && f == CaptureFormat::grey) continue;  // no colour in GREY
        if (multiplanar && offered_has(offered, multiplane_fourcc_of(f))) return Choice{f, multiplane_fourcc_of(f)};
        if (offered_has(offered, fourcc_of(f))) return Choice{f, fourcc_of(f)};
        if (offered_has(offered, multiplane_fourcc_of(f))) return Choice{f, multiplane_fourcc_of(f)};
    }
    return std::nullopt;
}

// The pixel formats (fourccs) the device offers for buffer type `type`, in its order (VIDIOC_ENUM_FMT).
std::vector<std::uint32_t> offered_formats(int fd, std::uint32_t type) {
    std::vector<std::uint32_t> offered;
    for (std::uint32_t i = 0;; ++i) {
        v4l2_fmtdesc desc{};
        desc.index = i;
        desc.type = type;
        if (xioctl(fd, VIDIOC_ENUM_FMT, &desc) == -1) break;  // EINVAL ends the list
        offered.push_back(desc.pixelformat);
    }
    return offered;
}

// The error when none of the configuration's formats is offered: what was wanted and what the device has.
std::string no_wanted_format(const std::string& device, const V4l2Config& config,
                             const std::vector<std::uint32_t>& offered) {
    std::string list;
    for (std::uint32_t f : offered) list += (list.empty() ? "" : ", ") + fourcc_name(f);
    std::string names;
    for (CaptureFormat f : config.formats) names += (names.empty() ? "" : "/") + pixel_format_name(f);
    return device + ": none of the wanted formats (" + names + (config.colour ? ", in colour" : "") +
           ") is offered; device has: " + (list.empty() ? std::string("none") : list);
}

}  // namespace

Status V4l2Capture::negotiate_format(const V4l2Config& config) {
    const std::vector<std::uint32_t> offered = offered_formats(fd_.get(), buf_type_);
    const std::optional<Choice> wanted = choose_format(config, offered, multiplanar_);
    if (!wanted) return make_error(ENOTSUP, no_wanted_format(device_, config, offered));
    v4l2_format fmt{};
    fmt.type = buf_type_;
    std::uint32_t got = 0;
    std::uint32_t field = 0;
    if (multiplanar_) {
        fmt.fmt.pix_mp.width = static_cast<std::uint32_t>(config.width);
        fmt.fmt.pix_mp.height = static_cast<std::uint32_t>(config.height);
        fmt.fmt.pix_mp.pixelformat = wanted->fourcc;
        fmt.fmt.pix_mp.field = V4L2_FIELD_NONE;
    } else {
        fmt.fmt.pix.width = static_cast<std::uint32_t>(config.width);
        fmt.fmt.pix.height = static_cast<std::uint32_t>(config.height);
        fmt.fmt.pix.pixelformat = wanted->fourcc;
        fmt.fmt.pix.field = V4L2_FIELD_NONE;
    }
    if (xioctl(fd_.get(), VIDIOC_S_FMT, &fmt) == -1) return errno_error(device_ + ": VIDIOC_S_FMT");
    if (multiplanar_) {
        const v4l2_pix_format_mplane& mp = fmt.fmt.pix_mp;
        got = mp.pixelformat;
        field = mp.field;
        width_ = static_cast<int>(mp.width);
        height_ = static_cast<int>(mp.height);
        plane_count_ = mp.num_planes;
        if (plane_count_ < 1 || plane_count_ > 3) {
            return make_error(ENOTSUP, device_ + ": VIDIOC_S_FMT: " + std::to_string(plane_count_) +
                                           " planes, at most 3 are supported");
        }
        for (int p = 0; p < plane_count_; ++p)
            plane_bytes_per_line_.push_back(static_cast<int>(mp.plane_fmt[p].bytesperline));
        encoding_ = ycbcr_encoding_from_v4l2(mp.colorspace, mp.ycbcr_enc, mp.quantization);
    } else {
        got = fmt.fmt.pix.pixelformat;
        field = fmt.fmt.pix.field;
        width_ = static_cast<int>(fmt.fmt.pix.width);
        height_ = static_cast<int>(fmt.fmt.pix.height);
        plane_bytes_per_line_ = {static_cast<int>(fmt.fmt.pix.bytesperline)};
        encoding_ = ycbcr_encoding_from_v4l2(fmt.fmt.pix.colorspace, fmt.fmt.pix.ycbcr_enc, fmt.fmt.pix.quantization);
    }
    if (got != wanted->fourcc) {
        return make_error(
            ENOTSUP, device_ + ": VIDIOC_S_FMT: asked " + fourcc_name(wanted->fourcc) + ", got " + fourcc_name(got));
    }
    if (field != V4L2_FIELD_NONE && field != V4L2_FIELD_ANY) {
        return make_error(ENOTSUP,
                          device_ + ": interlaced capture (field " + std::to_string(field) + ") is not supported");
    }
    format_ = wanted->format;
    bytes_per_line_ = plane_bytes_per_line_.front();
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
        parm.type = buf_type_;
        parm.parm.capture.timeperframe.numerator = 1;
        parm.parm.capture.timeperframe.denominator = static_cast<std::uint32_t>(config.frames_per_second);
        (void)xioctl(fd_.get(), VIDIOC_S_PARM, &parm);
    }
    return {};
}

Status V4l2Capture::map_buffer(std::uint32_t index) {
    v4l2_plane planes[VIDEO_MAX_PLANES]{};
    v4l2_buffer buf{};
    buf.type = buf_type_;
    buf.memory = V4L2_MEMORY_MMAP;
    buf.index = index;
    if (multiplanar_) {
        buf.m.planes = planes;
        buf.length = VIDEO_MAX_PLANES;
    }
    if (xioctl(fd_.get(), VIDIOC_QUERYBUF, &buf) == -1) {
        return errno_error(device_ + ": VIDIOC_QUERYBUF " + std::to_string(index));
    }
    std::vector<MappedBuffer> mapped;
    const int count = multiplanar_ ? static_cast<int>(buf.length) : 1;
    if (count != plane_count_) {
        return make_error(EIO, device_ + ": buffer " + std::to_string(index) + " has " + std::to_string(count) +
                                   " planes, the format " + std::to_string(plane_count_));
    }
    for (int p = 0; p < count; ++p) {
        const std::uint32_t length = multiplanar_ ? planes[p].length : buf.length;
        const auto offset = static_cast<off_t>(multiplanar_ ? planes[p].m.mem_offset : buf.m.offset);
        auto mapping = MappedBuffer::map(fd_.get(), length, offset);
        if (!mapping) {
            return with_context(mapping.error(),
                                device_ + ": buffer " + std::to_string(index) + " plane " + std::to_string(p));
        }
        mapped.push_back(std::move(mapping).value());
    }
    buffers_.push_back(std::move(mapped));
    return {};
}

Status V4l2Capture::start_streaming(const V4l2Config& config) {
    v4l2_requestbuffers req{};
    req.count = static_cast<std::uint32_t>(config.buffer_count);
    req.type = buf_type_;
    req.memory = V4L2_MEMORY_MMAP;
    if (xioctl(fd_.get(), VIDIOC_REQBUFS, &req) == -1) return errno_error(device_ + ": VIDIOC_REQBUFS (mmap)");
    if (req.count < 2) {
        return make_error(ENOMEM, device_ + ": VIDIOC_REQBUFS granted " + std::to_string(req.count) +
                                      " buffer(s), at least 2 are needed");
    }
    for (std::uint32_t i = 0; i < req.count; ++i) {
        if (Status s = map_buffer(i); !s) return s;
        if (Status s = requeue(i); !s) return s;
    }
    auto type = static_cast<v4l2_buf_type>(buf_type_);
    if (xioctl(fd_.get(), VIDIOC_STREAMON, &type) == -1) return errno_error(device_ + ": VIDIOC_STREAMON");
    streaming_ = true;
    return {};
}

V4l2Capture::~V4l2Capture() {
    if (streaming_) {
        auto type = static_cast<v4l2_buf_type>(buf_type_);
        (void)xioctl(fd_.get(), VIDIOC_STREAMOFF, &type);  // nothing to do on failure: the fd closes next
    }
}

Status V4l2Capture::requeue(std::uint32_t index) {
    v4l2_plane planes[VIDEO_MAX_PLANES]{};
    v4l2_buffer buf{};
    buf.type = buf_type_;
    buf.memory = V4L2_MEMORY_MMAP;
    buf.index = index;
    if (multiplanar_) {
        buf.m.planes = planes;
        buf.length = static_cast<std::uint32_t>(plane_count_);
    }
    if (xioctl(fd_.get(), VIDIOC_QBUF, &buf) == -1)
        return errno_error(device_ + ": VIDIOC_QBUF " + std::to_string(index));
    return {};
}

Status V4l2Capture::convert(std::uint32_t index, const std::uint32_t* bytes_used, const std::uint32_t* data_offset,
                            CameraFrame& frame) {
    // bytesused bounds a compressed frame; a driver that leaves it 0 for a raw format gets the
    // whole buffer (the layout checks still demand the full image).
    PlaneBytes planes[VIDEO_MAX_PLANES];
    for (int p = 0; p < plane_count_; ++p) {
        std::span<const std::uint8_t> bytes = buffers_[index][static_cast<std::size_t>(p)].bytes();
        if (bytes_used[p] != 0) bytes = bytes.first(std::min<std::size_t>(bytes.size(), bytes_used[p]));
        // Multi-planar: bytesused counts from the plane's start, the data from data_offset.
        bytes = bytes.subspan(std::min<std::size_t>(bytes.size(), data_offset[p]));
        planes[p] = {bytes, plane_bytes_per_line_[static_cast<std::size_t>(p)]};
    }
    const std::span<const std::uint8_t> bytes = planes[0].data;
    Status s;
    if (colour_) frame.colour.emplace();
    switch (format_) {
        case CaptureFormat::grey:
            s = grey_from_grey(bytes, width_, height_, bytes_per_line_, frame.image);
            if (s && colour_) rgb_from_grey(frame.image, *frame.colour);
            break;
        case CaptureFormat::yuyv:
            s = grey_from_yuyv(bytes, width_, height_, bytes_per_line_, frame.image);
            if (s && colour_) s = rgb_from_yuyv(bytes, width_, height_, bytes_per_line_, encoding_, *frame.colour);
            break;
        case CaptureFormat::mjpeg:
            s = colour_ ? mjpeg_->decode_colour(bytes, frame.image, *frame.colour, width_, height_)
                        : mjpeg_->decode_grey(bytes, frame.image, width_, height_);
            break;
        case CaptureFormat::nv12:
        case CaptureFormat::nv21:
        case CaptureFormat::yuv420:
        case CaptureFormat::yvu420:
            s = convert_yuv420(format_, std::span<const PlaneBytes>(planes, static_cast<std::size_t>(plane_count_)),
                               width_, height_, encoding_, frame.image, colour_ ? &*frame.colour : nullptr);
            break;
        case CaptureFormat::rgb24:
        case CaptureFormat::bgr24:
            s = convert_rgb24(format_, bytes, width_, height_, bytes_per_line_, frame.image,
                              colour_ ? &*frame.colour : nullptr);
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
        std::uint32_t used[VIDEO_MAX_PLANES]{};
        std::uint32_t offset[VIDEO_MAX_PLANES]{};
        bool have = false;
        std::uint32_t skipped = 0;
        for (;;) {
            v4l2_plane planes[VIDEO_MAX_PLANES]{};
            v4l2_buffer buf{};
            buf.type = buf_type_;
            buf.memory = V4L2_MEMORY_MMAP;
            if (multiplanar_) {
                buf.m.planes = planes;
                buf.length = static_cast<std::uint32_t>(plane_count_);
            }
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
            for (int p = 0; p < plane_count_; ++p) {
                used[p] = multiplanar_ ? planes[p].bytesused : buf.bytesused;
                offset[p] = multiplanar_ ? std::min(planes[p].data_offset, planes[p].bytesused) : 0;
            }
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
        const Status converted = convert(newest.index, used, offset, frame);
        if (Status s = requeue(newest.index); !s) return s.error();
        if (!converted) return converted.error();
        return frame;
    }
}

std::string V4l2Capture::description() const {
    std::string text = device_ + " (" + driver_ + ") " + std::to_string(width_) + "x" + std::to_string(height_) + " " +
                       pixel_format_name(format_);
    if (multiplanar_) text += " (" + std::to_string(plane_count_) + "-plane mplane)";
    if (colour_ || format_ != CaptureFormat::grey) text += " " + ycbcr_encoding_name(encoding_);
    if (colour_) text += ", colour";
    text += ", " + std::to_string(buffers_.size()) + " mmap buffers";
    if (!skipped_controls_.empty()) text += "; controls not on this device: " + skipped_controls_;
    return text;
}

Status V4l2Capture::apply_controls(const CameraControls& controls) {
    std::string skipped;
    if (Status s = apply_v4l2_controls(fd_.get(), device_, controls, &skipped); !s) return s;
    skipped_controls_ = skipped;
    return {};
}

CameraControlValues V4l2Capture::control_values() const { return read_v4l2_controls(fd_.get()); }

}  // namespace mogao
