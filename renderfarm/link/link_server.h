// SPDX-License-Identifier: Apache-2.0
// The farm side of the link: a gRPC server (service mogao.link.v1.Tour, mogao_link.proto) that
// accepts appliance sessions over mutual TLS on an IPv6 endpoint and answers their view requests
// with JPEG frames made by an injected renderer. See docs/link.md for the protocol and the PKI.
//
// Flow control, per session: only the NEWEST unrendered request is kept (a newer one replaces it;
// the replaced one is counted in requests_dropped), requests not newer than one already seen are
// dropped, and at most `max_frames_in_flight` frames are rendering or sent-but-unacknowledged
// (the appliance acknowledges frames in ViewRequestMsg.ack_frame_id once it has taken them), so a
// slow appliance or network never builds a queue of stale frames in the farm or in socket buffers.
//
// Threads: gRPC runs each session's handler on its own thread (it writes that session's frames);
// the handler starts one reader thread (requests and acks); `render_threads` workers shared by all
// sessions call the renderer, picking sessions round-robin. With render_threads = 1 (the default)
// the renderer is never called concurrently, which is what the MPI farm needs.
//
// Connections: the server accepts on its own socket (ConnectionGuard) and hands each connection
// to gRPC, so that connections and TLS handshakes in progress are capped (gRPC 1.51 has no cap).
//
// Errors: construction throws LinkError (bad endpoint, unusable TLS material or revocation list,
// bad connection limits, port taken). After
// that nothing is thrown: an invalid request is refused and logged (the session continues), a
// renderer exception costs that request its frame (RequestRefused: the session ends with
// RESOURCE_EXHAUSTED and the renderer's message, which the appliance logs), a broken session ends
// alone; all of it is logged to stderr through spdlog (logger "mogao-link").
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/link_types.h"
#include "common/view_request.h"
#include "renderfarm/link/cert_expiry.h"
#include "renderfarm/link/connection_guard.h"
#include "renderfarm/link/endpoint.h"
#include "renderfarm/link/tls_material.h"

namespace mogao {

// Thrown by a FrameRenderer that will not serve the session's requests (e.g. what it asks for costs
// more than the farm can give it): the link ends that session with RESOURCE_EXHAUSTED and what().
struct RequestRefused : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Renders and encodes one validated request. Called from the server's render threads; may throw
// (the request then gets no frame; RequestRefused ends the session, see above).
// ViewRequest::frame_id holds the appliance's request id.
using FrameRenderer = std::function<RenderedFrame(const ViewRequest&)>;

struct LinkServerOptions {
    // "[address]:port". On "[::]" gRPC opens one dual-stack socket (IPV6_V6ONLY = 0) and offers no
    // way to change that; see ipv6_only.
    std::string listen{kDefaultListenEndpoint};
    TlsMaterial tls;  // farm certificate + key; ca_pem: the CA every appliance certificate must chain to
    // Where `tls` was read from. When set, gRPC re-reads these files every tls_refresh_s seconds:
    // the farm's certificate is rotated by replacing the files (write a temporary, rename), without
    // a restart; open sessions continue, new handshakes get the new certificate. A key that does
    // not match its certificate is not taken (gRPC keeps the pair it has). Empty: `tls` only.
    TlsFilePaths tls_files;
    int tls_refresh_s = 60;  // 1..86400
    // Appliance certificate common names allowed in; empty = every certificate the CA issued.
    std::vector<std::string> allowed_appliances;
    // The farm CA's revocation list (PEM CRL, revocation.h); empty = none. Re-read when the file
    // changes: a listed certificate is refused, and its open sessions end (PERMISSION_DENIED).
    std::string crl_path;
    int render_threads = 1;        // renderer calls at once over all sessions, 1..64
    int max_frames_in_flight = 2;  // per session, 1..16
    int max_sessions = 8;          // concurrent appliance sessions; more are refused (RESOURCE_EXHAUSTED)
    // Concurrent sessions of one certificate (common name), 1..1024: one appliance cannot
    // take every slot. 2 lets a reconnecting appliance overlap the session it is leaving.
    int max_sessions_per_appliance = 2;
    int max_request_bytes = 64 * 1024;  // larger messages end that session (RESOURCE_EXHAUSTED)
    // Caps on TCP connections before gRPC sees them: in all, without an admitted session (TLS
    // handshakes in progress, peers that opened no session) and per source address of those
    // (connection_guard.h). Over a cap, a connection is closed before any TLS.
    ConnectionLimits connections;
    // Refuse sessions that arrive over IPv4 (an IPv4-mapped peer on the dual-stack [::] socket)
    // with PERMISSION_DENIED: the link is specified as IPv6 and the appliances' certificates and
    // firewall rules are written for IPv6 addresses.
    bool ipv6_only = true;
};

struct LinkServerStats {
    std::uint64_t sessions_opened = 0;   // sessions that reached the handler (TLS and checks passed)
    std::uint64_t sessions_refused = 0;  // IPv4 peer, name not allowed, revoked, too many sessions, stopping
    std::uint64_t sessions_revoked = 0;  // open sessions ended because their certificate got revoked
    std::uint64_t sessions_active = 0;
    std::uint64_t requests_received = 0;  // valid view requests read
    std::uint64_t requests_invalid = 0;   // refused by validation (logged)
    std::uint64_t requests_dropped = 0;   // stale: replaced before rendering, or not newer than one seen
    std::uint64_t render_calls = 0;
    std::uint64_t render_failures = 0;  // renderer threw or returned an unusable frame
    std::uint64_t frames_sent = 0;
    std::uint64_t jpeg_bytes_sent = 0;
    ConnectionGuardStats connections;  // TCP connections: accepted, refused by each cap, open now
    // The certificates the farm serves with: the CA bundle and its own, re-read from tls_files (at
    // most every tls_refresh_s) once rotated (cert_expiry.h, HeldCertificates).
    std::vector<CertificateExpiry> certificates;
    // nextUpdate of the revocation list in force (Unix seconds; 0: no list, or none in it).
    std::int64_t crl_next_update_s = 0;
};

class LinkServer {
public:
    // Validates the options, binds and starts serving. Throws LinkError naming the option.
    LinkServer(LinkServerOptions options, FrameRenderer renderer);
    ~LinkServer();  // stop()
    LinkServer(const LinkServer&) = delete;
    LinkServer& operator=(const LinkServer&) = delete;

    // The endpoint actually bound (with the port the kernel picked for port 0).
    [[nodiscard]] Endpoint endpoint() const;
    [[nodiscard]] LinkServerStats stats() const;
    // The certificate common name of open session `session` (ViewRequest::session), so that the
    // farm applies that appliance's view policy; empty once the session has closed, or for 0.
    [[nodiscard]] std::string appliance_of(std::uint64_t session) const;

    // Late binding, for a renderer that queues its calls (the farm's main thread serves every session's
    // call in turn): called when the renderer is about to start on a request of `session`, it takes the
    // newest request the session has sent since that call was made, if any. The renderer then renders
    // that one instead, and the frame answers it: the link labels the frame with its id, pose and
    // times, and counts the request the call was made for as dropped as stale. Without this, a
    // request waits in the renderer's queue while every other session's frame is rendered, and the
    // frame shows a view as old as that wait (motion-to-photon grows with the number of sessions).
    // Nullopt when the session has no newer request, is not in a renderer call, or has closed.
    // Thread-safe.
    [[nodiscard]] std::optional<ViewRequest> take_newer_request(std::uint64_t session);

    // Ends every session (appliances see UNAVAILABLE/CANCELLED and reconnect elsewhere or later),
    // waits for a renderer call in progress, closes the port. Idempotent.
    void stop();

private:
    struct Impl;
    static void start_server(Impl& impl, const Endpoint& endpoint);
    std::unique_ptr<Impl> impl_;
};

}  // namespace mogao
