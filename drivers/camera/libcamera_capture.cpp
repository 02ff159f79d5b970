// SPDX-License-Identifier: Apache-2.0
// LibcameraCapture with libcamera (MOGAO_HAVE_LIBCAMERA). See libcamera_capture.h for the design.
#include "drivers/camera/libcamera_capture.h"

#include <libcamera/camera.h>
#include <libcamera/camera_manager.h>
#include <libcamera/control_ids.h>
#include <libcamera/formats.h>
#include <libcamera/framebuffer.h>
#include <libcamera/framebuffer_allocator.h>
#include <libcamera/property_ids.h>
#include <libcamera/request.h>
#include <libcamera/stream.h>

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <map>
#include <mutex>

#include "common/mapped_buffer.h"
#include "drivers/camera/mjpeg_decoder.h"
#include "drivers/camera/pixel_format.h"

namespace mogao {

static_assert(libcamera_fourcc(CaptureFormat::grey) == libcamera::formats::R8.fourcc());
static_assert(libcamera_fourcc(CaptureFormat::yuyv) == libcamera::formats::YUYV.fourcc());
static_assert(libcamera_fourcc(CaptureFormat::mjpeg) == libcamera::formats::MJPEG.fourcc());
static_assert(libcamera_fourcc(CaptureFormat::nv12) == libcamera::formats::NV12.fourcc());
static_assert(libcamera_fourcc(CaptureFormat::nv21) == libcamera::formats::NV21.fourcc());
static_assert(libcamera_fourcc(CaptureFormat::yuv420) == libcamera::formats::YUV420.fourcc());
static_assert(libcamera_fourcc(CaptureFormat::yvu420) == libcamera::formats::YVU420.fourcc());
static_assert(libcamera_fourcc(CaptureFormat::rgb24) == libcamera::formats::BGR888.fourcc());
static_assert(libcamera_fourcc(CaptureFormat::bgr24) == libcamera::formats::RGB888.fourcc());

namespace {

// libcamera 0.0.x allows one CameraManager per process (a second one is a Fatal log: abort).
std::mutex g_manager_mutex;
bool g_manager_in_use = false;

// libcamera returns negative errno values.
Error libcamera_error(int ret, const std::string& what) {
    const int code = ret < 0 ? -ret : EIO;
    return make_error(code, what + ": " + std::strerror(code));
}

std::string format_list(const std::vector<libcamera::PixelFormat>& formats) {
    std::string list;
    for (const libcamera::PixelFormat& f : formats) list += (list.empty() ? "" : ", ") + f.toString();
    return list.empty() ? std::string("none") : list;
}

// Claims the process-wide CameraManager slot for a scope (false: another holder has it).
class ManagerClaim {
public:
    ManagerClaim() {
        const std::lock_guard<std::mutex> lock(g_manager_mutex);
        held_ = !g_manager_in_use;
        g_manager_in_use = true;
    }
    ManagerClaim(const ManagerClaim&) = delete;
    ManagerClaim& operator=(const ManagerClaim&) = delete;
    ~ManagerClaim() {
        if (!held_) return;
        const std::lock_guard<std::mutex> lock(g_manager_mutex);
        g_manager_in_use = false;
    }
    [[nodiscard]] bool held() const { return held_; }

private:
    bool held_ = false;
};

std::string describe_camera(libcamera::Camera& camera) {
    std::string out = "libcamera:" + camera.id() + "\n";
    if (const auto model = camera.properties().get(libcamera::properties::Model)) out += "  model: " + *model + "\n";
    const std::unique_ptr<libcamera::CameraConfiguration> config =
        camera.generateConfiguration({libcamera::StreamRole::Viewfinder});
    if (config && !config->empty()) {
        const libcamera::StreamFormats& formats = config->at(0).formats();
        out += "  Viewfinder stream formats (default " + config->at(0).toString() + "):\n";
        for (const libcamera::PixelFormat& f : formats.pixelformats())
            out += "    " + f.toString() + "  " + formats.range(f).toString() + "\n";
    } else {
        out += "  no Viewfinder stream configuration\n";
    }
    out += "  controls:\n";
    std::map<std::string, std::string> controls;  // sorted by name
    for (const auto& [id, info] : camera.controls()) controls[id->name()] = info.toString();
    for (const auto& [name, range] : controls) out += "    " + name + ": " + range + "\n";
    return out;
}

}  // namespace

Result<std::string> describe_libcamera_cameras(const std::string& camera_id) {
    const ManagerClaim claim;
    if (!claim.held()) {
        return make_error(EBUSY,
                          "libcamera: a LibcameraCapture is open in this process (libcamera 0.0.x allows "
                          "one CameraManager per process)");
    }
    libcamera::CameraManager manager;
    if (const int ret = manager.start(); ret < 0) return libcamera_error(ret, "libcamera: CameraManager::start");
    std::string out;
    std::string error;
    {
        std::vector<std::shared_ptr<libcamera::Camera>> cameras = manager.cameras();
        if (!camera_id.empty()) {
            std::shared_ptr<libcamera::Camera> one = manager.get(camera_id);
            std::string list;
            for (const auto& c : cameras) list += (list.empty() ? "" : ", ") + c->id();
            if (!one)
                error = "libcamera camera " + camera_id + ": not found; cameras: " + (list.empty() ? "none" : list);
            cameras = one ? std::vector{one} : std::vector<std::shared_ptr<libcamera::Camera>>{};
        } else if (cameras.empty()) {
            error =
                "libcamera: no camera found (CameraManager lists none: no supported camera attached, or its "
                "pipeline handler or IPA module is missing)";
        }
        for (const auto& c : cameras) out += describe_camera(*c);
    }  // every Camera reference is dropped before the manager stops
    manager.stop();
    if (!error.empty()) return make_error(ENODEV, error);
    return out;
}

bool libcamera_built_in() noexcept { return true; }

struct LibcameraCapture::Impl {
    struct Mapping {
        MappedBuffer map;  // [0, offset + length) of the plane's dmabuf
        std::size_t offset = 0;
        std::size_t length = 0;
    };

    // The process-wide CameraManager slot, claimed when the capture is made (open() gives EBUSY if
    // another holder has it); declared first so it is given back last.
    ManagerClaim slot;
    std::unique_ptr<libcamera::CameraManager> manager;
    bool manager_started = false;
    std::shared_ptr<libcamera::Camera> camera;
    bool acquired = false;
    std::unique_ptr<libcamera::CameraConfiguration> configuration;
    libcamera::Stream* stream = nullptr;
    std::unique_ptr<libcamera::FrameBufferAllocator> allocator;
    std::map<const libcamera::FrameBuffer*, std::vector<Mapping>> mappings;  // one per plane
    std::vector<std::unique_ptr<libcamera::Request>> requests;
    bool connected = false;
    bool started = false;
    std::unique_ptr<MjpegDecoder> mjpeg;  // only for MJPEG
    std::string id;
    CaptureFormat format = CaptureFormat::grey;
    int width = 0;
    int height = 0;
    int stride = 0;
    int timeout_ms = 2000;
    bool colour = false;
    YcbcrEncoding encoding;
    std::string skipped_controls;

    // Shared with libcamera's thread.
    std::mutex mutex;
    std::condition_variable ready;
    std::vector<libcamera::Request*> completed;  // capacity = requests.size(): push_back never allocates
    bool disconnected = false;

    std::vector<libcamera::Request*> taken;  // next_frame()'s copy of `completed` (same capacity)

    Impl() = default;
    Impl(const Impl&) = delete;
    Impl& operator=(const Impl&) = delete;

    ~Impl() {
        // stop() cancels the queued requests; they complete (RequestCancelled, ignored by the slot)
        // before it returns. Then nothing calls into this object any more.
        if (started) (void)camera->stop();
        if (connected) {
            camera->requestCompleted.disconnect(this);
            camera->disconnected.disconnect(this);
        }
        completed.clear();
        taken.clear();
        requests.clear();
        mappings.clear();  // unmap before the buffers are freed
        if (allocator && stream != nullptr) (void)allocator->free(stream);
        allocator.reset();
        configuration.reset();
        if (acquired) (void)camera->release();
        camera.reset();  // before the manager: it owns the pipeline handlers
        if (manager_started) manager->stop();
        manager.reset();
    }

    // libcamera's thread. Must not throw or block for long.
    void on_request_completed(libcamera::Request* request) {
        if (request->status() == libcamera::Request::RequestCancelled) return;  // camera stopping
        {
            const std::lock_guard<std::mutex> lock(mutex);
            if (completed.size() < completed.capacity()) completed.push_back(request);
        }
        ready.notify_one();
    }

    void on_disconnected() {
        {
            const std::lock_guard<std::mutex> lock(mutex);
            disconnected = true;
        }
        ready.notify_one();
    }

    Status requeue(libcamera::Request* request) {
        request->reuse(libcamera::Request::ReuseBuffers);
        if (const int ret = camera->queueRequest(request); ret < 0) {
            return libcamera_error(ret, "libcamera camera " + id + ": queueRequest");
        }
        return {};
    }

    [[nodiscard]] bool frame_ok(const libcamera::Request* request) const {
        if (request->status() != libcamera::Request::RequestComplete) return false;
        const libcamera::FrameBuffer* buffer = request->findBuffer(stream);
        return buffer != nullptr && buffer->metadata().status == libcamera::FrameMetadata::FrameSuccess &&
               mappings.count(buffer) != 0 && !mappings.at(buffer).empty();
    }

    Status convert(const libcamera::FrameBuffer& buffer, CameraFrame& frame) {
        const std::vector<Mapping>& maps = mappings.at(&buffer);
        const auto planes = buffer.metadata().planes();
        PlaneBytes bytes[3];
        const std::size_t count = std::min<std::size_t>(maps.size(), 3);
        for (std::size_t p = 0; p < count; ++p) {
            const Mapping& m = maps[p];
            std::span<const std::uint8_t> b = m.map.bytes().subspan(m.offset, m.length);
            // bytesused bounds a compressed frame; 0 means the whole plane.
            if (p < planes.size() && planes[p].bytesused != 0) {
                b = b.first(std::min<std::size_t>(b.size(), planes[p].bytesused));
            }
            // Chroma rows: a full stride when interleaved (NV12), half of it when planar (YUV420).
            const bool planar_chroma = p > 0 && (format == CaptureFormat::yuv420 || format == CaptureFormat::yvu420);
            bytes[p] = {b, planar_chroma ? stride / 2 : stride};
        }
        Status s = convert_planes(std::span<const PlaneBytes>(bytes, count), frame);
        if (!s) return make_error(EBADMSG, "libcamera camera " + id + ": " + s.error().message);
        return {};
    }

    Status convert_planes(std::span<const PlaneBytes> planes, CameraFrame& frame) {
        const std::span<const std::uint8_t> bytes = planes[0].data;
        if (colour) frame.colour.emplace();
        switch (format) {
            case CaptureFormat::grey: {
                Status s = grey_from_grey(bytes, width, height, stride, frame.image);
                if (s && colour) rgb_from_grey(frame.image, *frame.colour);
                return s;
            }
            case CaptureFormat::yuyv: {
                Status s = grey_from_yuyv(bytes, width, height, stride, frame.image);
                if (s && colour) s = rgb_from_yuyv(bytes, width, height, stride, encoding, *frame.colour);
                return s;
            }
            case CaptureFormat::mjpeg:
                return colour ? mjpeg->decode_colour(bytes, frame.image, *frame.colour, width, height)
                              : mjpeg->decode_grey(bytes, frame.image, width, height);
            case CaptureFormat::nv12:
            case CaptureFormat::nv21:
            case CaptureFormat::yuv420:
            case CaptureFormat::yvu420:
                return convert_yuv420(format, planes, width, height, encoding, frame.image,
                                      colour ? &*frame.colour : nullptr);
            case CaptureFormat::rgb24:
            case CaptureFormat::bgr24:
                return convert_rgb24(format, bytes, width, height, stride, frame.image,
                                     colour ? &*frame.colour : nullptr);
            case CaptureFormat::image_file:
                break;
        }
        return make_error(EINVAL, "image_file is not a capture format");
    }

    Status apply_controls(const CameraControls& wanted, libcamera::ControlList& out);
    Status configure(const LibcameraConfig& config);
    Status allocate_and_start(const LibcameraConfig& config);
};

LibcameraCapture::LibcameraCapture() : impl_(std::make_unique<Impl>()) {}
LibcameraCapture::~LibcameraCapture() = default;

Result<std::unique_ptr<LibcameraCapture>> LibcameraCapture::open(const LibcameraConfig& config) {
    if (Status s = check_libcamera_config(config); !s) return s.error();
    std::unique_ptr<LibcameraCapture> cam(new LibcameraCapture());
    Impl& d = *cam->impl_;
    d.timeout_ms = config.timeout_ms;
    if (!d.slot.held()) {
        return make_error(EBUSY,
                          "libcamera: another LibcameraCapture is open (libcamera 0.0.x allows one "
                          "CameraManager per process)");
    }

    d.manager = std::make_unique<libcamera::CameraManager>();
    if (const int ret = d.manager->start(); ret < 0) return libcamera_error(ret, "libcamera: CameraManager::start");
    d.manager_started = true;

    const std::vector<std::shared_ptr<libcamera::Camera>> cameras = d.manager->cameras();
    if (config.camera_id.empty()) {
        if (cameras.empty()) {
            return make_error(ENODEV,
                              "libcamera: no camera found (CameraManager lists none: no supported camera "
                              "attached, or its pipeline handler or IPA module is missing)");
        }
        d.camera = cameras.front();
    } else {
        d.camera = d.manager->get(config.camera_id);
        if (!d.camera) {
            std::string list;
            for (const auto& c : cameras) list += (list.empty() ? "" : ", ") + c->id();
            return make_error(ENODEV, "libcamera camera " + config.camera_id +
                                          ": not found; cameras: " + (list.empty() ? std::string("none") : list));
        }
    }
    d.id = d.camera->id();
    if (const int ret = d.camera->acquire(); ret < 0) {
        return libcamera_error(ret, "libcamera camera " + d.id + ": acquire (in use by another process?)");
    }
    d.acquired = true;
    if (Status s = d.configure(config); !s) return s.error();
    if (Status s = d.allocate_and_start(config); !s) return s.error();

    cam->camera_id_ = d.id;
    cam->format_ = d.format;
    cam->width_ = d.width;
    cam->height_ = d.height;
    cam->buffer_count_ = static_cast<int>(d.requests.size());
    return cam;
}

Status LibcameraCapture::Impl::configure(const LibcameraConfig& config) {
    const std::string name = "libcamera camera " + id;
    const libcamera::StreamRoles roles{libcamera::StreamRole::Viewfinder};
    configuration = camera->generateConfiguration(roles);
    if (!configuration || configuration->empty()) {
        return make_error(ENOTSUP, name + ": no Viewfinder stream configuration");
    }
    libcamera::StreamConfiguration& sc = configuration->at(0);
    const std::vector<libcamera::PixelFormat> offered_formats = sc.formats().pixelformats();
    std::vector<std::uint32_t> offered;
    for (const libcamera::PixelFormat& f : offered_formats) offered.push_back(f.fourcc());
    const std::optional<CaptureFormat> chosen = choose_libcamera_format(config.formats, offered, config.colour);
    if (!chosen) {
        std::string wanted_list;
        for (CaptureFormat f : config.formats) wanted_list += (wanted_list.empty() ? "" : "/") + pixel_format_name(f);
        return make_error(ENOTSUP, name + ": none of the wanted formats (" + wanted_list +
                                       (config.colour ? std::string(", in colour") : std::string()) +
                                       ") is offered; camera has: " + format_list(offered_formats));
    }
    const libcamera::PixelFormat wanted(libcamera_fourcc(*chosen));
    sc.pixelFormat = wanted;
    sc.size = libcamera::Size(static_cast<unsigned int>(config.width), static_cast<unsigned int>(config.height));
    sc.bufferCount = static_cast<unsigned int>(config.buffer_count);
    if (configuration->validate() == libcamera::CameraConfiguration::Invalid) {
        return make_error(EINVAL, name + ": the pipeline rejects " + wanted.toString() + " " +
                                      std::to_string(config.width) + "x" + std::to_string(config.height));
    }
    if (sc.pixelFormat != wanted) {
        return make_error(
            ENOTSUP, name + ": asked " + wanted.toString() + ", the pipeline adjusted to " + sc.pixelFormat.toString());
    }
    if (sc.size.width < 1 || sc.size.height < 1 || sc.size.width > kMaxCaptureDimension ||
        sc.size.height > kMaxCaptureDimension) {
        return make_error(EINVAL, name + ": pipeline chose size " + sc.size.toString() + ", outside [1, " +
                                      std::to_string(kMaxCaptureDimension) + "]");
    }
    format = *chosen;
    width = static_cast<int>(sc.size.width);
    height = static_cast<int>(sc.size.height);
    stride = static_cast<int>(sc.stride);
    colour = config.colour;
    // libcamera's colour space of the stream (JPEG: full-range BT.601, as decoded by TurboJPEG).
    if (sc.colorSpace) {
        const auto enc = sc.colorSpace->ycbcrEncoding;
        encoding.matrix = enc == libcamera::ColorSpace::YcbcrEncoding::Rec709    ? YcbcrMatrix::bt709
                          : enc == libcamera::ColorSpace::YcbcrEncoding::Rec2020 ? YcbcrMatrix::bt2020
                                                                                 : YcbcrMatrix::bt601;
        encoding.range =
            sc.colorSpace->range == libcamera::ColorSpace::Range::Full ? YcbcrRange::full : YcbcrRange::limited;
    }
    if (const int ret = camera->configure(configuration.get()); ret < 0) {
        return libcamera_error(ret, name + ": configure " + sc.toString());
    }
    stream = sc.stream();
    if (stream == nullptr) return make_error(EIO, name + ": configure left the stream unset");
    if (format == CaptureFormat::mjpeg) {
        auto decoder = MjpegDecoder::create();
        if (!decoder) return decoder.error();
        mjpeg = std::make_unique<MjpegDecoder>(std::move(decoder).value());
    }
    return {};
}

Status LibcameraCapture::Impl::allocate_and_start(const LibcameraConfig& config) {
    const std::string name = "libcamera camera " + id;
    allocator = std::make_unique<libcamera::FrameBufferAllocator>(camera);
    const int count = allocator->allocate(stream);
    if (count < 0) return libcamera_error(count, name + ": FrameBufferAllocator::allocate");
    if (count < 2) {
        return make_error(ENOMEM, name + ": " + std::to_string(count) + " buffer(s) allocated (asked " +
                                      std::to_string(config.buffer_count) + "), at least 2 are needed");
    }
    const std::vector<std::unique_ptr<libcamera::FrameBuffer>>& buffers = allocator->buffers(stream);
    for (std::size_t i = 0; i < buffers.size(); ++i) {
        const libcamera::FrameBuffer& buffer = *buffers[i];
        const std::string which = name + ": buffer " + std::to_string(i);
        // R8, YUYV and MJPEG have one plane; NV12/YUV420 two or three (often in one dmabuf).
        if (buffer.planes().empty() || buffer.planes().size() > 3) {
            return make_error(EIO, which + " has " + std::to_string(buffer.planes().size()) + " planes");
        }
        std::vector<Mapping> planes;
        for (const libcamera::FrameBuffer::Plane& plane : buffer.planes()) {
            const std::size_t offset =
                plane.offset == libcamera::FrameBuffer::Plane::kInvalidOffset ? 0 : std::size_t{plane.offset};
            auto map = MappedBuffer::map(plane.fd.get(), offset + plane.length, 0);
            if (!map) return with_context(map.error(), which);
            planes.push_back(Mapping{std::move(map).value(), offset, plane.length});
        }
        mappings.emplace(&buffer, std::move(planes));

        std::unique_ptr<libcamera::Request> request = camera->createRequest(i);
        if (!request) return make_error(ENOMEM, which + ": createRequest failed");
        if (const int ret = request->addBuffer(stream, buffers[i].get()); ret < 0) {
            return libcamera_error(ret, which + ": Request::addBuffer");
        }
        requests.push_back(std::move(request));
    }
    completed.reserve(requests.size());
    taken.reserve(requests.size());

    camera->requestCompleted.connect(this, &Impl::on_request_completed);
    camera->disconnected.connect(this, &Impl::on_disconnected);
    connected = true;
    libcamera::ControlList controls(camera->controls());
    if (Status s = apply_controls(config.controls, controls); !s) return s;
    if (const int ret = camera->start(&controls); ret < 0) return libcamera_error(ret, name + ": start");
    started = true;
    for (const auto& request : requests) {
        if (const int ret = camera->queueRequest(request.get()); ret < 0) {
            return libcamera_error(ret, name + ": queueRequest");
        }
    }
    return {};
}

Result<CameraFrame> LibcameraCapture::next_frame() {
    Impl& d = *impl_;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(d.timeout_ms);
    std::uint32_t skipped = 0;
    for (;;) {
        {
            std::unique_lock<std::mutex> lock(d.mutex);
            if (!d.ready.wait_until(lock, deadline, [&] { return !d.completed.empty() || d.disconnected; })) {
                return make_error(
                    ETIMEDOUT, "libcamera camera " + d.id + ": no frame for " + std::to_string(d.timeout_ms) + " ms");
            }
            if (d.disconnected) return make_error(ENODEV, "libcamera camera " + d.id + ": disconnected");
            d.taken.assign(d.completed.begin(), d.completed.end());  // within capacity: no allocation
            d.completed.clear();
        }
        // Keep the newest good frame, give every other request straight back.
        libcamera::Request* newest = nullptr;
        for (libcamera::Request* request : d.taken) {
            if (!d.frame_ok(request)) {
                if (Status s = d.requeue(request); !s) return s.error();
                ++skipped;
                continue;
            }
            if (newest != nullptr) {
                if (Status s = d.requeue(newest); !s) return s.error();
                ++skipped;
            }
            newest = request;
        }
        d.taken.clear();
        if (newest == nullptr) continue;  // only failed frames: wait for the next

        const libcamera::FrameBuffer& buffer = *newest->findBuffer(d.stream);
        CameraFrame frame;
        frame.format = d.format;
        frame.sequence = buffer.metadata().sequence;
        frame.skipped = skipped;
        frame.timestamp_ns = libcamera_frame_timestamp_ns(newest->metadata().get(libcamera::controls::SensorTimestamp),
                                                          buffer.metadata().timestamp);
        frame.clock = TimestampSource::kernel_monotonic;
        const Status converted = d.convert(buffer, frame);
        if (Status s = d.requeue(newest); !s) return s.error();
        if (!converted) return converted.error();
        return frame;
    }
}

std::string LibcameraCapture::description() const {
    std::string text = "libcamera " + camera_id_ + " " + std::to_string(width_) + "x" + std::to_string(height_) + " " +
                       pixel_format_name(format_) + (impl_->colour ? ", colour" : "") + ", " +
                       std::to_string(buffer_count_) + " dmabuf buffers";
    if (!impl_->skipped_controls.empty()) text += "; controls not on this camera: " + impl_->skipped_controls;
    return text;
}

// libcamera controls (control_ids.h): AeEnable switches exposure and gain together; ExposureTime
// (us, int32) and AnalogueGain (float, 1.0 = unity) set them manually; AwbEnable switches white
// balance. With AeEnable or AwbEnable false and no manual value the pipeline holds its last values
// (lock). libcamera 0.0.3 cannot set a colour temperature: manual white balance is ENOTSUP.
Status LibcameraCapture::Impl::apply_controls(const CameraControls& wanted, libcamera::ControlList& out) {
    using Mode = ControlSetting::Mode;
    const libcamera::ControlInfoMap& info = camera->controls();
    const auto missing = [&](const ControlSetting& s, const std::string& what) -> Status {
        if (s.required)
            return make_error(ENOTSUP, "libcamera camera " + id + ": " + s.name + " = " + describe(s) +
                                           ": the camera has no " + what);
        skipped_controls += (skipped_controls.empty() ? "" : ", ") + s.name + " (no " + what + ")";
        return {};
    };
    // A value within the camera's range; a default (not required) outside it is clamped and noted.
    const auto in_range = [&](const ControlSetting& s, double lo, double hi,
                              const std::string& unit) -> Result<double> {
        if (s.value >= lo && s.value <= hi) return s.value;
        if (!s.required) {
            const double clamped = s.value < lo ? lo : hi;
            skipped_controls +=
                (skipped_controls.empty() ? "" : ", ") + s.name + " clamped to " + std::to_string(clamped) + unit;
            return clamped;
        }
        return make_error(EINVAL, "libcamera camera " + id + ": " + s.name + " = " + std::to_string(s.value) +
                                      " is outside the camera's range [" + std::to_string(lo) + ", " +
                                      std::to_string(hi) + "]" + unit);
    };
    const bool has_ae = info.count(&libcamera::controls::AeEnable) != 0;
    const ControlSetting& e = wanted.exposure;
    const ControlSetting& g = wanted.gain;
    if (e.mode != Mode::keep || g.mode == Mode::manual || g.mode == Mode::lock) {
        if (!has_ae) {
            if (Status s = missing(e.mode != Mode::keep ? e : g, "AeEnable control"); !s) return s;
        } else {
            out.set(libcamera::controls::AeEnable, e.mode == Mode::automatic && g.mode != Mode::lock);
        }
    }
    if (e.mode == Mode::manual) {
        const auto it = info.find(&libcamera::controls::ExposureTime);
        if (it == info.end()) {
            if (Status s = missing(e, "ExposureTime control"); !s) return s;
        } else {
            const libcamera::ControlInfo& ci = it->second;
            auto v = in_range(e, ci.min().get<int32_t>(), ci.max().get<int32_t>(), " us");
            if (!v) return v.error();
            out.set(libcamera::controls::ExposureTime, static_cast<int32_t>(std::lround(*v)));
        }
    }
    if (g.mode == Mode::manual) {
        const auto it = info.find(&libcamera::controls::AnalogueGain);
        if (it == info.end()) {
            if (Status s = missing(g, "AnalogueGain control"); !s) return s;
        } else {
            const libcamera::ControlInfo& ci = it->second;
            auto v = in_range(g, ci.min().get<float>(), ci.max().get<float>(), "");
            if (!v) return v.error();
            out.set(libcamera::controls::AnalogueGain, static_cast<float>(*v));
        }
    }
    const ControlSetting& w = wanted.white_balance;
    if (w.mode == Mode::manual) {
        return make_error(ENOTSUP, "libcamera camera " + id + ": " + w.name +
                                       ": libcamera 0.0.3 cannot set a colour temperature (use lock or auto)");
    }
    if (w.mode != Mode::keep) {
        if (info.count(&libcamera::controls::AwbEnable) == 0) return missing(w, "AwbEnable control");
        out.set(libcamera::controls::AwbEnable, w.mode == Mode::automatic);
    }
    return {};
}

}  // namespace mogao
