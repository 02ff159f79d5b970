// SPDX-License-Identifier: Apache-2.0
// ConnectionGuard: the farm's own listening socket, in front of gRPC, with caps on the TCP
// connections it hands over (a cap on connections and on handshakes in progress).
//
// Why: gRPC 1.51 (Debian 12) accepts without limit; every connection costs a TLS handshake (CPU)
// and buffers (memory) before anything learns who the peer is. gRPC has no cap option in 1.51
// (grpc.max_allowed_incoming_connections came later), but it can take connections accepted out of
// band (grpc::experimental::ExternalConnectionAcceptor, FROM_FD); the guard accepts on its own
// socket, refuses what is over a cap by closing it at once, and hands the rest to gRPC.
//
// What is counted:
//   open            every connection handed over and not yet closed;
//   unauthenticated  open connections on which no session has been admitted yet (TLS handshake in
//                    progress, a peer that completed it but opened no session, or one refused by
//                    the service): the pre-authentication state an anonymous peer can hold.
// A session admitted on a connection (LinkServer calls authenticated(peer)) moves it out of the
// unauthenticated count for good. Caps: `max_connections` (open), `max_unauthenticated` (all peers)
// and `max_unauthenticated_per_address` (one source address: one host cannot take every
// pre-authentication slot). A connection still unauthenticated after `unauthenticated_max_age_s`
// is shut down by the guard itself (a backstop beside gRPC's 10 s handshake timeout: a peer that
// passes TLS with a valid certificate but never opens a session would otherwise keep its slot).
//
// How a close is seen: the guard keeps a dup() of each connection's socket and polls it for
// EPOLLHUP only (it never reads: the bytes are gRPC's). gRPC shuts a connection down (shutdown
// SHUT_RDWR) before closing its descriptor, and a peer's reset or a full close does the same to the
// socket, so EPOLLHUP marks the end either way; the guard then closes its dup. Checked by
// ConnectionGuard tests that count connections back to zero.
//
// Peers are named as gRPC names them in ServerContext::peer() after LinkServer's readable_peer():
// "ipv6:[addr]:port", or "ipv4:a.b.c.d:port" for an IPv4-mapped peer on a dual-stack socket.
//
// Errors: the constructor throws LinkError naming the option or the socket call (bad limits, port
// in use, address not local, IPv6 disabled). After that nothing throws: a failing accept() is
// logged (rate-limited) and accepting goes on; refusals are logged at powers of two per reason.
#pragma once

#include <netinet/in.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "common/unique_fd.h"
#include "renderfarm/link/endpoint.h"

namespace mogao {

struct ConnectionLimits {
    int max_connections = 64;                 // open connections in all, 1..65536
    int max_unauthenticated = 16;             // without an admitted session, all peers, 1..max_connections
    int max_unauthenticated_per_address = 4;  // of one source address, 1..max_unauthenticated
    double unauthenticated_max_age_s = 30.0;  // then the guard shuts the connection down, 1..3600
    // On the wildcard "[::]": also accept IPv4 peers (IPV6_V6ONLY = 0) so that the service can refuse
    // them with PERMISSION_DENIED and a reason (LinkServerOptions::ipv6_only), as gRPC's own socket did.
    bool dual_stack_wildcard = true;
};

struct ConnectionGuardStats {
    std::uint64_t accepted = 0;                 // handed to gRPC
    std::uint64_t refused_open = 0;             // over max_connections
    std::uint64_t refused_unauthenticated = 0;  // over max_unauthenticated
    std::uint64_t refused_per_address = 0;      // over max_unauthenticated_per_address
    std::uint64_t aged_out = 0;                 // shut down after unauthenticated_max_age_s
    std::uint64_t open = 0;                     // now
    std::uint64_t unauthenticated = 0;          // now
};

class ConnectionGuard {
public:
    // Takes ownership of an accepted connection (O_CLOEXEC, non-blocking) that came in on the
    // listening socket `listener_fd`. Called on the guard's thread.
    using Handoff = std::function<void(UniqueFd connection, int listener_fd)>;

    // Validates the limits, binds `at` (SO_REUSEADDR, never SO_REUSEPORT: a second farm on the port
    // fails here), listens and starts the accepting thread. Throws LinkError.
    ConnectionGuard(const Endpoint& at, ConnectionLimits limits, Handoff handoff);
    ~ConnectionGuard();  // stop()
    ConnectionGuard(const ConnectionGuard&) = delete;
    ConnectionGuard& operator=(const ConnectionGuard&) = delete;

    [[nodiscard]] std::uint16_t port() const;  // the port bound (the kernel's pick for port 0)
    [[nodiscard]] ConnectionGuardStats stats() const;

    // A session was admitted on the connection from `peer` (see the naming above). Unknown peers
    // are ignored (a connection that closed meanwhile). Any thread.
    void authenticated(const std::string& peer);

    // Stops accepting, closes the listening socket and the guard's dups (gRPC keeps its own
    // descriptors). Idempotent.
    void stop();

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// "ipv6:[addr]:port" or, for an IPv4-mapped address, "ipv4:a.b.c.d:port" (gRPC's peer naming).
[[nodiscard]] std::string grpc_peer_name(const sockaddr_in6& address);

}  // namespace mogao
