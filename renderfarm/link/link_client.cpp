// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/link/link_client.h"

#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <array>
#include <condition_variable>
#include <ctime>
#include <deque>
#include <filesystem>
#include <mutex>
#include <optional>
#include <random>
#include <thread>

#include "renderfarm/link/endpoint.h"
#include "renderfarm/link/link_log.h"
#include "renderfarm/link/mogao_link.grpc.pb.h"
#include "renderfarm/link/wire_convert.h"

namespace mogao {
namespace {

namespace v1 = link::v1;
using Stream = grpc::ClientReaderWriter<v1::ViewRequestMsg, v1::FrameMsg>;

struct Sample {
    std::int64_t receive_ns;
    std::size_t bytes;
    double latency_ms;
};

}  // namespace

struct LinkClient::Impl {
    LinkClientOptions options;
    FrameCallback on_frame;
    Endpoint endpoint;
    std::shared_ptr<grpc::ChannelCredentials> credentials;
    grpc::ChannelArguments channel_args;

    mutable std::mutex mutex;
    std::condition_variable cv;
    bool stopping = false;
    bool session_over = false;               // the current stream ended: the writer leaves
    grpc::ClientContext* current = nullptr;  // the call stop() cancels
    std::uint64_t next_request_id = 1;
    std::optional<ViewRequest> latest;   // newest submitted; re-sent after a reconnect if unanswered
    std::optional<ViewRequest> unsent;   // newest not yet written on the current stream
    std::uint64_t ack_due = 0;           // frame id to acknowledge on the current stream (0: none)
    std::uint64_t newest_delivered = 0;  // request id of the newest frame handed to the callback
    LinkClientStats stats;
    std::deque<Sample> window;
    std::mt19937_64 rng{std::random_device{}()};

    std::jthread thread;

    // tls_files' modification times when last looked at (connection thread and writer, under mutex).
    std::array<std::filesystem::file_time_type, 3> tls_stamp{};
    bool rotate = false;  // the session ended for rotated TLS material: reconnect without backoff
    std::chrono::steady_clock::time_point next_tls_check;  // writer thread

    void run();
    bool reload_tls();   // true when rotated material was taken (see LinkClientOptions::tls_files)
    bool run_session();  // true when a session was established
    void write_loop(Stream& stream);
    void on_frame_msg(v1::FrameMsg& msg);
    void record(const Sample& sample, std::uint64_t request_id);  // with mutex held
};

std::array<std::filesystem::file_time_type, 3> file_stamps(const TlsFilePaths& files) {
    std::array<std::filesystem::file_time_type, 3> out{};
    std::error_code ec;
    out[0] = std::filesystem::last_write_time(files.ca, ec);
    out[1] = std::filesystem::last_write_time(files.cert, ec);
    out[2] = std::filesystem::last_write_time(files.key, ec);
    return out;
}

bool LinkClient::Impl::reload_tls() {
    if (options.tls_files.empty()) return false;
    const auto stamp = file_stamps(options.tls_files);
    {
        const std::lock_guard lock(mutex);
        if (stamp == tls_stamp) return false;
        tls_stamp = stamp;  // a bad set is refused once, not at every look
    }
    TlsMaterial fresh;
    std::string error;
    try {
        fresh = load_tls_files(options.tls_files.ca, options.tls_files.cert, options.tls_files.key);
        error = check_tls_material(fresh, "rotated appliance TLS").error;
    } catch (const std::exception& e) {
        error = e.what();
    }
    const std::lock_guard lock(mutex);
    if (!error.empty()) {
        ++stats.tls_reloads_refused;
        link_log().error("TLS files changed but not taken ({}); keeping the certificate in use", error);
        return false;
    }
    if (fresh.cert_pem == options.tls.cert_pem && fresh.key_pem == options.tls.key_pem &&
        fresh.ca_pem == options.tls.ca_pem)
        return false;  // touched, not changed
    grpc::SslCredentialsOptions ssl;
    ssl.pem_root_certs = fresh.ca_pem;
    ssl.pem_private_key = fresh.key_pem;
    ssl.pem_cert_chain = fresh.cert_pem;
    credentials = grpc::SslCredentials(ssl);
    options.tls = std::move(fresh);
    stats.certificates = certificate_expiries(options.tls, "appliance");
    ++stats.tls_reloads;
    link_log().info("TLS files changed: {} taken for the next session", options.tls_files.cert.string());
    return true;
}

void LinkClient::Impl::run() {
    auto backoff = options.initial_backoff;
    for (;;) {
        (void)reload_tls();
        if (run_session()) backoff = options.initial_backoff;
        std::unique_lock lock(mutex);
        if (stopping) return;
        if (std::exchange(rotate, false)) {
            link_log().info("reconnecting to the farm at {} with the rotated certificate", endpoint.to_string());
            continue;
        }
        std::uniform_real_distribution<double> jitter(1.0 - options.backoff_jitter, 1.0 + options.backoff_jitter);
        const auto wait =
            std::chrono::milliseconds(static_cast<std::int64_t>(static_cast<double>(backoff.count()) * jitter(rng)));
        backoff = std::min(backoff * 2, options.max_backoff);
        stats.next_backoff = backoff;
        link_log().info("reconnecting to the farm at {} in {} ms", endpoint.to_string(), wait.count());
        if (cv.wait_for(lock, wait, [&] { return stopping; })) return;
    }
}

bool LinkClient::Impl::run_session() {
    // A fresh channel per attempt (with a private subchannel pool): our backoff alone decides when
    // to retry, not the backoff state of a shared gRPC subchannel.
    std::shared_ptr<grpc::ChannelCredentials> creds;
    {
        const std::lock_guard lock(mutex);
        creds = credentials;
    }
    const auto channel = grpc::CreateCustomChannel(endpoint.grpc_target(), creds, channel_args);
    const auto stub = v1::Tour::NewStub(channel);
    grpc::ClientContext ctx;
    {
        const std::lock_guard lock(mutex);
        if (stopping) return false;
        current = &ctx;  // TryCancel before the call starts is remembered by gRPC
        session_over = false;
        ack_due = 0;  // frame ids are per session
    }
    const auto stream = stub->Session(&ctx);
    stream->WaitForInitialMetadata();
    const auto& metadata = ctx.GetServerInitialMetadata();
    const auto schema = metadata.find("mogao-link-schema");
    const bool established = schema != metadata.end() && schema->second == "1";
    std::optional<std::jthread> writer;
    if (established) {
        {
            const std::lock_guard lock(mutex);
            stats.connected = true;
            ++stats.sessions_opened;
            // The newest request may have been lost with the last connection: send it again unless
            // it was already answered.
            if (latest && latest->frame_id > newest_delivered) unsent = latest;
        }
        link_log().info("connected to the farm at {}", endpoint.to_string());
        writer.emplace([&] { write_loop(*stream); });
        v1::FrameMsg msg;
        while (stream->Read(&msg)) on_frame_msg(msg);
    }
    {
        const std::lock_guard lock(mutex);
        session_over = true;
        stats.connected = false;
        if (!established) ++stats.attempts_failed;
    }
    cv.notify_all();
    ctx.TryCancel();  // a writer blocked in Write returns
    writer.reset();   // joins
    const grpc::Status status = stream->Finish();
    {
        const std::lock_guard lock(mutex);
        current = nullptr;
        if (stopping) return established;
    }
    if (established) {
        link_log().warn("farm session at {} ended: {} ({})", endpoint.to_string(), status.error_message(),
                        static_cast<int>(status.error_code()));
    } else {
        link_log().warn("cannot open a session with the farm at {}: {} ({})", endpoint.to_string(),
                        status.error_message(), static_cast<int>(status.error_code()));
    }
    return established;
}

void LinkClient::Impl::write_loop(Stream& stream) {
    for (;;) {
        v1::ViewRequestMsg msg;
        {
            std::unique_lock lock(mutex);
            cv.wait_until(lock, next_tls_check, [&] { return session_over || stopping || unsent || ack_due != 0; });
            if (session_over || stopping) return;
            if (std::chrono::steady_clock::now() >= next_tls_check) {
                // Every tls_refresh_s, busy or not: look at the TLS files (three stat calls).
                next_tls_check = std::chrono::steady_clock::now() + std::chrono::seconds(options.tls_refresh_s);
                lock.unlock();
                if (reload_tls()) {
                    const std::lock_guard relock(mutex);
                    rotate = true;
                    if (current != nullptr) current->TryCancel();  // the reader ends the session
                    return;
                }
                continue;
            }
            if (!unsent && ack_due == 0) continue;
            if (unsent) {
                view_to_msg(*unsent, msg);
                unsent.reset();
                ++stats.requests_sent;
            }
            msg.set_ack_frame_id(std::exchange(ack_due, 0));
        }
        if (!stream.Write(msg)) return;  // the stream broke; the reader sees it too
    }
}

void LinkClient::Impl::on_frame_msg(v1::FrameMsg& msg) {
    const std::int64_t receive_ns = realtime_ns();
    const std::uint64_t frame_id = msg.frame_id();
    LinkFrame frame;
    const std::string error = frame_from_msg(msg, frame);
    frame.times.receive_ns = receive_ns;
    bool deliver = false;
    {
        const std::lock_guard lock(mutex);
        if (!error.empty()) {
            ++stats.frames_discarded;
            link_log().warn("discarded frame {} from the farm: {}", frame_id, error);
        } else if (frame.request_id <= newest_delivered) {
            ++stats.frames_discarded;  // answers a request older than one already shown
        } else {
            newest_delivered = frame.request_id;
            deliver = true;
        }
    }
    if (deliver) {
        const Sample sample{
            receive_ns, frame.jpeg.size(),
            frame.times.request_ns > 0 ? static_cast<double>(receive_ns - frame.times.request_ns) / 1e6 : 0.0};
        const std::uint64_t request_id = frame.request_id;
        try {
            on_frame(std::move(frame));
        } catch (const std::exception& e) {
            link_log().error("frame callback failed on frame {} (request {}): {}", frame_id, request_id, e.what());
        } catch (...) {
            link_log().error("frame callback failed on frame {} with a non-standard exception", frame_id);
        }
        // Counted once the callback returned: stats().last_request_id == id means "shown".
        const std::lock_guard lock(mutex);
        record(sample, request_id);
    }
    // Acknowledge even discarded frames: the farm counts them against its in-flight window.
    const std::lock_guard lock(mutex);
    ack_due = std::max(ack_due, frame_id);
    cv.notify_all();
}

void LinkClient::Impl::record(const Sample& sample, std::uint64_t request_id) {
    ++stats.frames_received;
    stats.bytes_received += sample.bytes;
    stats.last_request_id = request_id;
    stats.last_latency_ms = sample.latency_ms;
    window.push_back(sample);
    while (window.size() > options.stats_window) window.pop_front();
    double latency_sum = 0, latency_max = 0, bytes = 0;
    for (const auto& s : window) {
        latency_sum += s.latency_ms;
        latency_max = std::max(latency_max, s.latency_ms);
        bytes += static_cast<double>(s.bytes);
    }
    const auto n = static_cast<double>(window.size());
    stats.mean_latency_ms = latency_sum / n;
    stats.max_latency_ms = latency_max;
    stats.mean_frame_bytes = bytes / n;
    // Rates over the window's span: n frames are n - 1 intervals, and the first frame's bytes
    // arrived before the span began.
    const double span_s = static_cast<double>(window.back().receive_ns - window.front().receive_ns) / 1e9;
    if (window.size() >= 2 && span_s > 0) {
        stats.fps = (n - 1) / span_s;
        stats.bandwidth_bytes_per_s = (bytes - static_cast<double>(window.front().bytes)) / span_s;
    }
}

LinkClient::LinkClient(LinkClientOptions options, FrameCallback on_frame) : impl_(std::make_unique<Impl>()) {
    if (!on_frame) throw LinkError("LinkClient: no frame callback");
    std::string error;
    const auto endpoint = parse_endpoint(options.endpoint, &error);
    if (!endpoint) throw LinkError("LinkClientOptions.endpoint: " + error);
    if (endpoint->port == 0 || endpoint->is_wildcard()) {
        throw LinkError("LinkClientOptions.endpoint: '" + options.endpoint +
                        "' is not a farm address (port 0 or [::])");
    }
    if (options.initial_backoff.count() < 1 || options.max_backoff < options.initial_backoff) {
        throw LinkError("LinkClientOptions: backoff must satisfy 1 ms <= initial_backoff <= max_backoff");
    }
    if (!(options.backoff_jitter >= 0.0 && options.backoff_jitter < 1.0)) {
        throw LinkError("LinkClientOptions.backoff_jitter must be in [0, 1)");
    }
    if (options.stats_window < 2) throw LinkError("LinkClientOptions.stats_window must be >= 2");
    if (options.tls_refresh_s < 1 || options.tls_refresh_s > 86'400)
        throw LinkError("LinkClientOptions.tls_refresh_s must be in [1, 86400]");
    const TlsCheck tls = check_tls_material(options.tls, "appliance TLS");
    if (!tls.error.empty()) throw LinkError(tls.error);
    // Expired or foreign certificates are the farm's to refuse; say why up front, keep trying
    // (the appliance's clock may be what is wrong, and NTP may fix it).
    for (const auto& warning : tls.warnings) link_log().warn("{}", warning);
    const auto held = certificate_expiries(options.tls, "appliance");
    for (const auto& warning : expiry_warnings(held, std::time(nullptr), kCertificateWarningSeconds))
        link_log().warn("appliance TLS: {}", warning);

    auto& impl = *impl_;
    impl.stats.certificates = held;
    impl.options = std::move(options);
    impl.on_frame = std::move(on_frame);
    impl.endpoint = *endpoint;
    grpc::SslCredentialsOptions ssl;
    ssl.pem_root_certs = impl.options.tls.ca_pem;
    ssl.pem_private_key = impl.options.tls.key_pem;
    ssl.pem_cert_chain = impl.options.tls.cert_pem;
    impl.credentials = grpc::SslCredentials(ssl);
    auto& args = impl.channel_args;
    args.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);
    args.SetMaxReceiveMessageSize(static_cast<int>(kMaxFrameJpegBytes + (64u << 10)));
    args.SetInt(GRPC_ARG_KEEPALIVE_TIME_MS, 10'000);  // notice a vanished farm within ~15 s
    args.SetInt(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, 5'000);
    args.SetInt(GRPC_ARG_MIN_RECONNECT_BACKOFF_MS, 5'000);  // gRPC's connect timeout: 20 s by default
    if (!impl.options.server_name.empty()) args.SetSslTargetNameOverride(impl.options.server_name);
    impl.stats.next_backoff = impl.options.initial_backoff;
    if (!impl.options.tls_files.empty()) impl.tls_stamp = file_stamps(impl.options.tls_files);
    impl.thread = std::jthread([&impl] { impl.run(); });
}

LinkClient::~LinkClient() { stop(); }

std::uint64_t LinkClient::submit(ViewRequest request, std::string* error) {
    auto& impl = *impl_;
    if (request.request_time_ns == 0) request.request_time_ns = realtime_ns();
    const std::lock_guard lock(impl.mutex);
    request.frame_id = impl.next_request_id;
    if (std::string why = validate_link_request(request); !why.empty()) {
        link_log().error("view request refused before sending: {}", why);
        if (error) *error = std::move(why);
        return 0;
    }
    ++impl.next_request_id;
    ++impl.stats.requests_submitted;
    if (impl.unsent) ++impl.stats.requests_coalesced;
    impl.latest = request;
    impl.unsent = std::move(request);
    impl.cv.notify_all();
    return impl.latest->frame_id;
}

LinkClientStats LinkClient::stats() const {
    const std::lock_guard lock(impl_->mutex);
    return impl_->stats;
}

void LinkClient::stop() {
    {
        const std::lock_guard lock(impl_->mutex);
        if (impl_->stopping) return;
        impl_->stopping = true;
        if (impl_->current) impl_->current->TryCancel();
    }
    impl_->cv.notify_all();
    if (impl_->thread.joinable()) impl_->thread.join();
}

}  // namespace mogao
