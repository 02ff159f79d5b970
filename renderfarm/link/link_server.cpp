// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/link/link_server.h"

#include <fmt/format.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/security/server_credentials.h>
#include <grpcpp/security/tls_certificate_provider.h>
#include <grpcpp/security/tls_credentials_options.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <ctime>
#include <deque>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

#include "renderfarm/link/link_log.h"
#include "renderfarm/link/mogao_link.grpc.pb.h"
#include "renderfarm/link/revocation.h"
#include "renderfarm/link/wire_convert.h"

namespace mogao {
namespace {

namespace v1 = link::v1;
using Stream = grpc::ServerReaderWriter<v1::FrameMsg, v1::ViewRequestMsg>;

// Log the first few occurrences of a per-session problem, then only at powers of two: a broken
// appliance sending 60 bad requests a second must not flood the journal.
bool worth_logging(std::uint64_t count) { return count <= 4 || (count & (count - 1)) == 0; }

struct SessionState {
    std::uint64_t id = 0;
    std::string peer;                         // "ipv6:[addr]:port"
    std::string identity;                     // certificate CN
    std::string serial;                       // certificate serial number (hex), checked against the revocation list
    std::uint64_t revocation_generation = 0;  // of the list last checked against (reader thread only)
    bool revoked = false;
    std::optional<ViewRequest> pending;
    std::int64_t pending_received_ns = 0;
    std::uint64_t newest_request_id = 0;
    std::uint64_t last_frame_id = 0;  // frames queued or sent
    std::uint64_t acked_frame_id = 0;
    bool rendering = false;
    // The newer request a renderer call took over (LinkServer::take_newer_request): what its frame answers.
    std::optional<ViewRequest> answering;
    std::int64_t answering_received_ns = 0;
    std::deque<v1::FrameMsg> outbox;  // rendered, waiting for the handler thread to write
    bool closed = false;
    std::string close_reason;
    std::string refused;  // the renderer refused the session (RequestRefused): the status sent
    std::uint64_t requests = 0, invalid = 0, dropped = 0, frames = 0, failures = 0, bad_acks = 0;

    [[nodiscard]] std::uint64_t in_flight() const { return (rendering ? 1 : 0) + (last_frame_id - acked_frame_id); }
    [[nodiscard]] std::string name() const {
        return "session " + std::to_string(id) + " (" + identity + " " + peer + ")";
    }
};

}  // namespace

struct LinkServer::Impl final : v1::Tour::Service {
    LinkServerOptions options;
    FrameRenderer renderer;
    Endpoint endpoint;
    std::unique_ptr<RevocationWatcher> revocation;   // null without LinkServerOptions::crl_path
    std::unique_ptr<HeldCertificates> certificates;  // for stats()

    mutable std::mutex mutex;
    std::condition_variable work_cv;  // render workers: a session became ready, or stopping
    std::condition_variable out_cv;   // session handlers: a frame is queued, or a session closed
    std::vector<std::shared_ptr<SessionState>> sessions;
    std::size_t next_pick = 0;
    std::uint64_t next_session_id = 1;
    bool stopping = false;
    LinkServerStats totals;

    std::unique_ptr<grpc::Server> server;  // declared after the service base: destroyed first
    std::unique_ptr<grpc::experimental::ExternalConnectionAcceptor> acceptor;  // gRPC's end of the guard's handoff
    std::unique_ptr<ConnectionGuard> guard;  // after server and acceptor: destroyed (stopped) before them
    std::vector<std::jthread> workers;

    grpc::Status Session(grpc::ServerContext* ctx, Stream* stream) override;
    grpc::Status admit(grpc::ServerContext* ctx, std::shared_ptr<SessionState>& out);
    void read_loop(SessionState& s, Stream& stream);
    void on_message(SessionState& s, const v1::ViewRequestMsg& msg);
    bool still_trusted(SessionState& s);
    void close(SessionState& s, const std::string& reason);
    void render_loop();
    std::shared_ptr<SessionState> pick_ready();  // with mutex held
    // The request and receive time a renderer call took over from `s` (take_newer_request), cleared.
    std::optional<std::pair<ViewRequest, std::int64_t>> take_answering(SessionState& s);
    std::optional<v1::FrameMsg> render(SessionState& s, ViewRequest request, std::int64_t received_ns,
                                       std::string& refused);
};

namespace {

std::string common_name(const grpc::ServerContext& ctx) {
    const auto auth = ctx.auth_context();
    if (!auth) return "?";
    const auto names = auth->FindPropertyValues("x509_common_name");
    return names.empty() ? "?" : std::string(names.front().data(), names.front().size());
}

std::string peer_serial(const grpc::ServerContext& ctx) {
    const auto auth = ctx.auth_context();
    if (!auth) return {};
    const auto pems = auth->FindPropertyValues("x509_pem_cert");
    return pems.empty() ? std::string{} : cert_serial_hex(std::string(pems.front().data(), pems.front().size()));
}

// gRPC percent-encodes the brackets of IPv6 peers ("ipv6:%5B::1%5D:5000"); logs read better without.
std::string readable_peer(std::string peer) {
    for (const auto& [from, to] : {std::pair{"%5B", "["}, std::pair{"%5D", "]"}}) {
        if (const auto at = peer.find(from); at != std::string::npos) peer.replace(at, 3, to);
    }
    return peer;
}

void check_options(const LinkServerOptions& o) {
    const auto range = [](const char* name, int v, int lo, int hi) {
        if (v < lo || v > hi) {
            throw LinkError(fmt::format("LinkServerOptions.{} = {} is outside [{}, {}]", name, v, lo, hi));
        }
    };
    range("render_threads", o.render_threads, 1, 64);
    range("max_frames_in_flight", o.max_frames_in_flight, 1, 16);
    range("max_sessions", o.max_sessions, 1, 1024);
    range("max_request_bytes", o.max_request_bytes, 1024, 16 << 20);
    range("tls_refresh_s", o.tls_refresh_s, 1, 86'400);
    range("max_sessions_per_appliance", o.max_sessions_per_appliance, 1, 1024);
    if (!o.tls_files.empty() && (o.tls_files.ca.empty() || o.tls_files.key.empty())) {
        throw LinkError("LinkServerOptions.tls_files: give the CA, certificate and key paths together");
    }
}

// Mutual TLS through gRPC's certificate providers: the material in memory, or files gRPC re-reads
// (rotation without a restart). Appliances must present a certificate that chains to the CA.
std::shared_ptr<grpc::ServerCredentials> server_credentials(const LinkServerOptions& o) {
    namespace ex = grpc::experimental;
    std::shared_ptr<ex::CertificateProviderInterface> provider;
    if (o.tls_files.empty()) {
        provider = std::make_shared<ex::StaticDataCertificateProvider>(
            o.tls.ca_pem, std::vector<ex::IdentityKeyCertPair>{{o.tls.key_pem, o.tls.cert_pem}});
    } else {
        provider = std::make_shared<ex::FileWatcherCertificateProvider>(
            o.tls_files.key.string(), o.tls_files.cert.string(), o.tls_files.ca.string(),
            static_cast<unsigned>(o.tls_refresh_s));
    }
    ex::TlsServerCredentialsOptions tls(provider);
    tls.watch_root_certs();
    tls.watch_identity_key_cert_pairs();
    tls.set_cert_request_type(GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY);
    return ex::TlsServerCredentials(tls);
}

}  // namespace

grpc::Status LinkServer::Impl::admit(grpc::ServerContext* ctx, std::shared_ptr<SessionState>& out) {
    auto s = std::make_shared<SessionState>();
    s->peer = readable_peer(ctx->peer());
    s->identity = common_name(*ctx);
    const auto refuse = [&](grpc::StatusCode code, const std::string& why) {
        link_log().warn("refused {} from {}: {}", s->identity, s->peer, why);
        const std::lock_guard lock(mutex);
        ++totals.sessions_refused;
        return grpc::Status(code, why);
    };
    // gRPC writes IPv4-mapped peers of the dual-stack socket as "ipv4:a.b.c.d:port".
    if (options.ipv6_only && !s->peer.starts_with("ipv6:")) {
        return refuse(grpc::StatusCode::PERMISSION_DENIED, "the mogao link is IPv6-only");
    }
    const auto& allowed = options.allowed_appliances;
    if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), s->identity) == allowed.end()) {
        return refuse(grpc::StatusCode::PERMISSION_DENIED,
                      "appliance '" + s->identity + "' is not in the allowed list");
    }
    if (revocation) {
        s->serial = peer_serial(*ctx);
        s->revocation_generation = revocation->generation();
        if (s->serial.empty() || revocation->revoked(s->serial)) {
            return refuse(grpc::StatusCode::PERMISSION_DENIED, "certificate " + s->serial + " of '" + s->identity +
                                                                   "' is revoked (" + revocation->path().string() +
                                                                   ")");
        }
    }
    {
        const std::lock_guard lock(mutex);
        if (stopping) return grpc::Status(grpc::StatusCode::UNAVAILABLE, "farm is shutting down");
        const auto same = std::count_if(sessions.begin(), sessions.end(),
                                        [&](const auto& other) { return other->identity == s->identity; });
        if (same >= options.max_sessions_per_appliance) {
            ++totals.sessions_refused;
            link_log().warn("refused {} from {}: it already has {} sessions", s->identity, s->peer, same);
            return grpc::Status(
                grpc::StatusCode::RESOURCE_EXHAUSTED,
                fmt::format("'{}' already has {} sessions (the most one appliance may hold)", s->identity, same));
        }
        if (sessions.size() < static_cast<std::size_t>(options.max_sessions)) {
            s->id = next_session_id++;
            sessions.push_back(s);
            if (guard) guard->authenticated(s->peer);
            ++totals.sessions_opened;
            totals.sessions_active = sessions.size();
            out = s;
            return grpc::Status::OK;
        }
    }
    return refuse(grpc::StatusCode::RESOURCE_EXHAUSTED, "too many sessions");
}

grpc::Status LinkServer::Impl::Session(grpc::ServerContext* ctx, Stream* stream) {
    std::shared_ptr<SessionState> s;
    if (auto status = admit(ctx, s); !status.ok()) return status;
    // Initial metadata right away: the appliance takes it as "session established" and resets its
    // reconnect backoff, before any frame exists.
    ctx->AddInitialMetadata("mogao-link-schema", "1");
    stream->SendInitialMetadata();
    link_log().info("{} opened", s->name());

    std::jthread reader([&] { read_loop(*s, *stream); });
    for (;;) {
        v1::FrameMsg frame;
        {
            std::unique_lock lock(mutex);
            out_cv.wait(lock, [&] { return s->closed || !s->outbox.empty(); });
            if (s->closed) break;  // unsent frames are stale once the session ends
            frame = std::move(s->outbox.front());
            s->outbox.pop_front();
        }
        frame.set_send_ns(realtime_ns());
        const auto bytes = frame.jpeg().size();
        if (!stream->Write(frame)) {
            close(*s, "write failed (appliance gone)");
            break;
        }
        const std::lock_guard lock(mutex);
        ++s->frames;
        ++totals.frames_sent;
        totals.jpeg_bytes_sent += bytes;
    }
    ctx->TryCancel();  // unblocks the reader's Read when the appliance is still connected
    reader.join();
    bool server_stopping = false;
    std::string summary;
    {
        // A render worker may still hold this session (it counts failures under the lock), so the
        // counters are read under the lock too.
        const std::lock_guard lock(mutex);
        std::erase(sessions, s);
        totals.sessions_active = sessions.size();
        server_stopping = stopping;
        summary =
            fmt::format("{} closed: {}; {} requests, {} dropped as stale, {} invalid, {} frames, {} render failures",
                        s->name(), s->close_reason, s->requests, s->dropped, s->invalid, s->frames, s->failures);
    }
    link_log().info("{}", summary);
    if (s->revoked) return grpc::Status(grpc::StatusCode::PERMISSION_DENIED, "the appliance's certificate was revoked");
    if (!s->refused.empty()) return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED, s->refused);
    return server_stopping ? grpc::Status(grpc::StatusCode::UNAVAILABLE, "farm is shutting down") : grpc::Status::OK;
}

void LinkServer::Impl::read_loop(SessionState& s, Stream& stream) {
    v1::ViewRequestMsg msg;
    while (stream.Read(&msg)) {
        if (!still_trusted(s)) return;
        on_message(s, msg);
    }
    // Read fails on a clean half-close, on cancellation and on a message above max_request_bytes
    // (gRPC then ends the call with RESOURCE_EXHAUSTED and logs it).
    close(s, "appliance stream ended");
}

bool LinkServer::Impl::still_trusted(SessionState& s) {
    if (!revocation) return true;
    const std::uint64_t generation = revocation->generation();
    if (generation == s.revocation_generation) return true;
    s.revocation_generation = generation;
    if (!revocation->revoked(s.serial)) return true;
    link_log().warn("{}: certificate {} revoked ({}); ending the session", s.name(), s.serial,
                    revocation->path().string());
    {
        const std::lock_guard lock(mutex);
        s.revoked = true;
        ++totals.sessions_revoked;
    }
    close(s, "certificate revoked");
    return false;
}

void LinkServer::Impl::on_message(SessionState& s, const v1::ViewRequestMsg& msg) {
    const std::int64_t now = realtime_ns();
    ViewRequest request;
    std::string error;
    if (msg.request_id() != 0) error = view_from_msg(msg, request);

    const std::lock_guard lock(mutex);
    if (msg.ack_frame_id() != 0) {
        // Acks are cumulative; one beyond what was sent is a client bug: clamp, so it can only
        // hurt that client (by starving its own flow control), never the farm.
        if (msg.ack_frame_id() > s.last_frame_id && worth_logging(++s.bad_acks)) {
            link_log().warn("{}: ack of frame {} beyond last frame {}", s.name(), msg.ack_frame_id(), s.last_frame_id);
        }
        s.acked_frame_id = std::max(s.acked_frame_id, std::min(msg.ack_frame_id(), s.last_frame_id));
        work_cv.notify_all();
    }
    if (msg.request_id() == 0) return;
    if (!error.empty()) {
        ++totals.requests_invalid;
        if (worth_logging(++s.invalid)) {
            link_log().warn("{}: request {} refused: {}", s.name(), msg.request_id(), error);
        }
        return;
    }
    if (request.frame_id <= s.newest_request_id) {  // reordered or replayed: never render the past
        ++s.dropped;
        ++totals.requests_dropped;
        return;
    }
    if (s.pending) {
        ++s.dropped;
        ++totals.requests_dropped;
    }
    s.pending = std::move(request);
    s.pending_received_ns = now;
    s.newest_request_id = s.pending->frame_id;
    ++s.requests;
    ++totals.requests_received;
    work_cv.notify_all();
}

void LinkServer::Impl::close(SessionState& s, const std::string& reason) {
    const std::lock_guard lock(mutex);
    if (!s.closed) {
        s.closed = true;
        s.close_reason = reason;
    }
    out_cv.notify_all();
}

std::shared_ptr<SessionState> LinkServer::Impl::pick_ready() {
    // Round-robin from the session after the last one served, so one busy appliance cannot starve
    // another when render_threads is smaller than the number of sessions.
    const auto limit = static_cast<std::uint64_t>(options.max_frames_in_flight);
    for (std::size_t i = 0; i < sessions.size(); ++i) {
        const std::size_t k = (next_pick + i) % sessions.size();
        auto& s = sessions[k];
        if (!s->closed && s->pending && !s->rendering && s->in_flight() < limit) {
            next_pick = k + 1;
            return s;
        }
    }
    return nullptr;
}

void LinkServer::Impl::render_loop() {
    for (;;) {
        std::shared_ptr<SessionState> s;
        ViewRequest request;
        std::int64_t received_ns = 0;
        {
            std::unique_lock lock(mutex);
            work_cv.wait(lock, [&] { return stopping || (s = pick_ready()) != nullptr; });
            if (stopping) return;
            request = std::move(*s->pending);
            request.session = s->id;  // the farm keys its per-session state on it
            s->pending.reset();
            received_ns = s->pending_received_ns;
            s->rendering = true;
            ++totals.render_calls;
        }
        std::string refused;
        auto frame = render(*s, request, received_ns, refused);
        const std::lock_guard lock(mutex);
        s->rendering = false;
        if (!refused.empty() && !s->closed) {
            s->refused = refused;
            s->closed = true;
            s->close_reason = "refused by the farm: " + refused;
            out_cv.notify_all();
        }
        if (!frame) {
            ++s->failures;
            ++totals.render_failures;
        } else if (!s->closed) {
            frame->set_frame_id(++s->last_frame_id);
            s->outbox.push_back(std::move(*frame));
            out_cv.notify_all();
        }
        work_cv.notify_all();  // the session may have a newer request waiting
    }
}

std::optional<v1::FrameMsg> LinkServer::Impl::render(SessionState& s, ViewRequest request, std::int64_t received_ns,
                                                     std::string& refused) {
    const std::int64_t start_ns = realtime_ns();
    RenderedFrame rendered;
    try {
        rendered = renderer(request);
    } catch (const RequestRefused& e) {
        take_answering(s);  // no frame: the newer request it took is dropped with it
        link_log().warn("{}: request {}: refused: {}", s.name(), request.frame_id, e.what());
        refused = e.what();
        return std::nullopt;
    } catch (const std::exception& e) {
        take_answering(s);
        link_log().error("{}: request {}: renderer failed: {}", s.name(), request.frame_id, e.what());
        return std::nullopt;
    } catch (...) {
        take_answering(s);
        link_log().error("{}: request {}: renderer failed with a non-standard exception", s.name(), request.frame_id);
        return std::nullopt;
    }
    const std::int64_t end_ns = realtime_ns();
    if (auto answered = take_answering(s)) {  // the renderer took a newer request: the frame answers that
        request = std::move(answered->first);
        received_ns = answered->second;
    }
    const auto side_ok = [](int v) { return v >= 1 && v <= kMaxLinkImageSide; };
    if (rendered.jpeg.empty() || rendered.jpeg.size() > kMaxFrameJpegBytes || !side_ok(rendered.size.width) ||
        !side_ok(rendered.size.height)) {
        link_log().error("{}: request {}: renderer returned an unusable frame ({}x{}, {} JPEG bytes)", s.name(),
                         request.frame_id, rendered.size.width, rendered.size.height, rendered.jpeg.size());
        return std::nullopt;
    }
    v1::FrameMsg frame;
    frame.set_request_id(request.frame_id);
    pose_to_msg(request.pose, *frame.mutable_pose());
    frame.set_request_time_ns(request.request_time_ns);
    frame.set_received_ns(received_ns);
    frame.set_render_start_ns(start_ns);
    frame.set_render_end_ns(rendered.render_end_ns != 0 ? rendered.render_end_ns : end_ns);
    frame.set_encode_end_ns(end_ns);
    frame.set_width(static_cast<std::uint32_t>(rendered.size.width));
    frame.set_height(static_cast<std::uint32_t>(rendered.size.height));
    frame.set_spp(rendered.spp);
    frame.set_bounces(rendered.bounces);
    frame.mutable_jpeg()->assign(reinterpret_cast<const char*>(rendered.jpeg.data()), rendered.jpeg.size());
    return frame;
}

// gRPC serves only connections the guard hands over (no listening port of its own): the guard
// binds first, so a taken port fails here, and caps what gRPC gets (connection_guard.h).
void LinkServer::start_server(Impl& impl, const Endpoint& endpoint) {
    grpc::ServerBuilder builder;
    using Type = grpc::ServerBuilder::experimental_type::ExternalConnectionType;
    impl.acceptor =
        builder.experimental().AddExternalConnectionAcceptor(Type::FROM_FD, server_credentials(impl.options));
    builder.RegisterService(&impl);
    builder.SetMaxReceiveMessageSize(impl.options.max_request_bytes);
    // A peer that connects and never finishes the TLS handshake (a port scan, garbage) is dropped
    // after 10 s instead of gRPC's 120 s.
    builder.AddChannelArgument(GRPC_ARG_SERVER_HANDSHAKE_TIMEOUT_MS, 10'000);
    // Detect a vanished appliance (power cut, cable) within ~15 s, and accept its own keepalive
    // pings (LinkClient pings every 10 s).
    builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIME_MS, 10'000);
    builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, 5'000);
    builder.AddChannelArgument(GRPC_ARG_HTTP2_MIN_RECV_PING_INTERVAL_WITHOUT_DATA_MS, 5'000);
    builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_PERMIT_WITHOUT_CALLS, 1);
    impl.server = builder.BuildAndStart();
    if (!impl.server || !impl.acceptor) throw LinkError("gRPC did not start (its reason is logged above)");
    auto* acceptor = impl.acceptor.get();
    impl.guard = std::make_unique<ConnectionGuard>(
        endpoint, impl.options.connections, [acceptor](UniqueFd connection, int listener_fd) {
            grpc::experimental::ExternalConnectionAcceptor::NewConnectionParameters p;
            p.listener_fd = listener_fd;
            p.fd = connection.release();  // gRPC owns and closes it
            acceptor->HandleNewConnection(&p);
        });
    impl.endpoint.port = impl.guard->port();
}

LinkServer::LinkServer(LinkServerOptions options, FrameRenderer renderer) : impl_(std::make_unique<Impl>()) {
    check_options(options);
    if (!renderer) throw LinkError("LinkServer: no renderer");
    std::string error;
    const auto endpoint = parse_endpoint(options.listen, &error);
    if (!endpoint) throw LinkError("LinkServerOptions.listen: " + error);
    const TlsCheck tls = check_tls_material(options.tls, "farm TLS");
    if (!tls.error.empty()) throw LinkError(tls.error);
    for (const auto& warning : tls.warnings) link_log().warn("{}", warning);
    impl_->certificates = std::make_unique<HeldCertificates>(options.tls, options.tls_files, "farm",
                                                             std::chrono::seconds(options.tls_refresh_s));
    for (const auto& warning :
         expiry_warnings(impl_->certificates->current(), std::time(nullptr), kCertificateWarningSeconds))
        link_log().warn("farm TLS: {}", warning);

    impl_->options = std::move(options);
    impl_->renderer = std::move(renderer);
    impl_->endpoint = *endpoint;
    if (!impl_->options.crl_path.empty()) {
        impl_->revocation = std::make_unique<RevocationWatcher>(impl_->options.crl_path, impl_->options.tls.ca_pem);
    }

    start_server(*impl_, *endpoint);
    for (int i = 0; i < impl_->options.render_threads; ++i) {
        impl_->workers.emplace_back([this] { impl_->render_loop(); });
    }
    link_log().info("serving the mogao link on {} ({} render thread(s), {} frames in flight per session{})",
                    impl_->endpoint.to_string(), impl_->options.render_threads, impl_->options.max_frames_in_flight,
                    impl_->endpoint.is_wildcard() && impl_->options.ipv6_only ? ", IPv4 peers refused" : "");
}

LinkServer::~LinkServer() { stop(); }

Endpoint LinkServer::endpoint() const { return impl_->endpoint; }

LinkServerStats LinkServer::stats() const {
    LinkServerStats stats;
    {
        const std::lock_guard lock(impl_->mutex);
        stats = impl_->totals;
    }
    if (impl_->guard) stats.connections = impl_->guard->stats();
    stats.certificates = impl_->certificates->current();
    if (impl_->revocation) stats.crl_next_update_s = impl_->revocation->next_update_s();
    return stats;
}

std::optional<std::pair<ViewRequest, std::int64_t>> LinkServer::Impl::take_answering(SessionState& s) {
    const std::lock_guard lock(mutex);
    if (!s.answering) return std::nullopt;
    std::optional<std::pair<ViewRequest, std::int64_t>> out{{std::move(*s.answering), s.answering_received_ns}};
    s.answering.reset();
    return out;
}

std::optional<ViewRequest> LinkServer::take_newer_request(std::uint64_t session) {
    const std::lock_guard lock(impl_->mutex);
    for (auto& s : impl_->sessions) {
        if (s->id != session) continue;
        if (s->closed || !s->rendering || !s->pending) return std::nullopt;
        // The request the call was made for (or one taken over before) is now stale.
        ++s->dropped;
        ++impl_->totals.requests_dropped;
        s->answering = std::move(*s->pending);
        s->answering->session = s->id;
        s->answering_received_ns = s->pending_received_ns;
        s->pending.reset();
        return s->answering;
    }
    return std::nullopt;
}

std::string LinkServer::appliance_of(std::uint64_t session) const {
    const std::lock_guard lock(impl_->mutex);
    for (const auto& s : impl_->sessions) {
        if (s->id == session) return s->identity;
    }
    return {};
}

void LinkServer::stop() {
    {
        const std::lock_guard lock(impl_->mutex);
        if (impl_->stopping) return;
        impl_->stopping = true;
        for (auto& s : impl_->sessions) {
            s->closed = true;
            s->close_reason = "farm stopping";
        }
    }
    impl_->out_cv.notify_all();
    impl_->work_cv.notify_all();
    if (impl_->guard) impl_->guard->stop();  // no new connections while gRPC shuts down
    // Handlers return as soon as they see their session closed; the deadline only bounds a handler
    // stuck in Write to a peer that stopped reading (gRPC then cancels its call).
    if (impl_->server) impl_->server->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(2));
    impl_->workers.clear();  // joins; a renderer call in progress finishes first
    link_log().info("stopped serving on {}", impl_->endpoint.to_string());
}

}  // namespace mogao
