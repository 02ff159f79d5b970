// SPDX-License-Identifier: Apache-2.0
// The appliance side of the link: connects to the farm's LinkServer over mutual TLS on IPv6,
// streams view requests (latest wins) and hands every frame to a callback, reconnecting by itself
// with exponential backoff whenever the farm goes away. See docs/link.md.
//
// Ordering guarantee: frames reach the callback in strictly increasing request id order, across
// reconnects and farm restarts (a frame answering a request older than one already delivered is
// discarded), so no frame is ever shown twice or after a newer one.
//
// Threads: one connection thread (connects, reads frames, runs the callback, sleeps the backoff)
// and, while connected, one writer thread. The callback runs on the connection thread: it may
// decode and display, but must not call stop() or destroy the client. Its return acknowledges the
// frame to the farm, which keeps at most 2 frames unacknowledged: a slow display slows the farm
// down instead of queueing stale frames.
//
// Errors: the constructor throws LinkError for a bad endpoint or unusable TLS material. Afterwards
// nothing is thrown: connection failures, farm refusals and malformed frames are logged to stderr
// (spdlog logger "mogao-link"), counted in LinkClientStats, and followed by a reconnect.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common/link_types.h"
#include "common/view_request.h"
#include "renderfarm/link/cert_expiry.h"
#include "renderfarm/link/tls_material.h"

namespace mogao {

struct LinkClientOptions {
    std::string endpoint;  // the farm, "[address]:port", e.g. "[2001:db8::5]:7443"
    TlsMaterial tls;       // this appliance's certificate + key; ca_pem: the farm CA
    // Where `tls` was read from. When set, the client looks at the files' modification times every
    // tls_refresh_s seconds (and before each connection attempt): a changed set that loads and
    // passes check_tls_material replaces `tls`, and an open session is ended at once and
    // re-opened with it (no backoff; the appliance keeps its last frame meanwhile), so an
    // appliance's certificate is rotated by replacing the files, without a restart. A set that
    // does not load or check is logged and not taken: the client keeps the last good material.
    TlsFilePaths tls_files;
    int tls_refresh_s = 10;  // 1..86400
    // Name the farm's certificate must carry. Empty: the endpoint's address, matched against the
    // certificate's IP SANs (pki issue-farm --san). Otherwise a DNS SAN, e.g. "farm-1".
    std::string server_name;
    // Reconnect backoff: initial, doubled after each failed attempt up to max, each wait scaled by
    // a random factor in [1 - jitter, 1 + jitter] so that a museum's appliances do not reconnect in
    // lockstep after a farm restart. Reset to initial once a session is established. Max 0.5 s: a
    // farm restarted over its surviving hosts listens again within seconds (docs/services.md), and
    // the wall waits on average half a wait past that for its next attempt; two attempts a second
    // are nothing for a farm to answer.
    std::chrono::milliseconds initial_backoff{250};
    std::chrono::milliseconds max_backoff{500};
    double backoff_jitter = 0.2;     // [0, 1)
    std::size_t stats_window = 120;  // frames over which fps, bandwidth and latency are averaged, >= 2
};

struct LinkClientStats {
    bool connected = false;
    std::uint64_t sessions_opened = 0;      // successful connects (reconnects = sessions_opened - 1)
    std::uint64_t attempts_failed = 0;      // connects refused or broken before the session was established
    std::uint64_t tls_reloads = 0;          // rotated TLS material taken from tls_files
    std::uint64_t tls_reloads_refused = 0;  // changed files that did not load or check (last good kept)
    std::uint64_t requests_submitted = 0;
    std::uint64_t requests_sent = 0;
    std::uint64_t requests_coalesced = 0;  // replaced by a newer one before they could be sent
    std::uint64_t frames_received = 0;     // delivered to the callback (counted when it returns)
    std::uint64_t frames_discarded = 0;    // malformed, or answering a request older than one delivered
    std::uint64_t bytes_received = 0;      // JPEG bytes delivered
    std::uint64_t last_request_id = 0;     // of the last frame whose callback returned
    // Over the last stats_window frames (0 until two frames arrived):
    double last_latency_ms = 0;  // request_time_ns (appliance clock) -> frame receipt (appliance clock)
    double mean_latency_ms = 0;
    double max_latency_ms = 0;
    double fps = 0;
    double mean_frame_bytes = 0;
    double bandwidth_bytes_per_s = 0;  // JPEG payload
    std::chrono::milliseconds next_backoff{0};
    // The certificates in use (the CA bundle and this appliance's own, rotated ones once taken),
    // for the status file's expiry report (cert_expiry.h).
    std::vector<CertificateExpiry> certificates;
};

using FrameCallback = std::function<void(LinkFrame&& frame)>;

class LinkClient {
public:
    // Checks the options and starts connecting in the background. Throws LinkError.
    LinkClient(LinkClientOptions options, FrameCallback on_frame);
    ~LinkClient();  // stop()
    LinkClient(const LinkClient&) = delete;
    LinkClient& operator=(const LinkClient&) = delete;

    // Makes `request` the newest view to render, replacing one not yet sent. The client assigns
    // the request id (request.frame_id is overwritten: ids increase across reconnects) and stamps
    // request_time_ns with CLOCK_REALTIME when it is 0. While disconnected the newest request waits
    // and is sent on connect. Returns the id, or 0 when the request is invalid (the reason is
    // logged and stored in *error when given; see validate_link_request for the limits).
    std::uint64_t submit(ViewRequest request, std::string* error = nullptr);

    [[nodiscard]] LinkClientStats stats() const;

    // Cancels the session and joins the threads. Idempotent. Not from the frame callback.
    void stop();

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace mogao
