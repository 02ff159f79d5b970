// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/link/connection_guard.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <map>
#include <mutex>
#include <thread>

#include <fmt/format.h>

#include "common/link_types.h"
#include "renderfarm/link/link_log.h"

namespace mogao {
namespace {

using Clock = std::chrono::steady_clock;

// Log the first few of each refusal, then only at powers of two: a flood must not flood the journal.
bool worth_logging(std::uint64_t count) { return count <= 4 || (count & (count - 1)) == 0; }

void check_limits(const ConnectionLimits& l) {
    const auto range = [](const char* name, double v, double lo, double hi) {
        if (!(v >= lo && v <= hi)) {
            throw LinkError(fmt::format("ConnectionLimits.{} = {} is outside [{}, {}]", name, v, lo, hi));
        }
    };
    range("max_connections", l.max_connections, 1, 65536);
    range("max_unauthenticated", l.max_unauthenticated, 1, l.max_connections);
    range("max_unauthenticated_per_address", l.max_unauthenticated_per_address, 1, l.max_unauthenticated);
    range("unauthenticated_max_age_s", l.unauthenticated_max_age_s, 1.0, 3600.0);
}

std::string sys_error(const std::string& what) { return what + ": " + std::strerror(errno); }

UniqueFd bind_and_listen(const Endpoint& at, bool dual_stack_wildcard) {
    UniqueFd fd(::socket(AF_INET6, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0));
    if (!fd.valid()) throw LinkError(sys_error("cannot listen on " + at.to_string() + ": socket(AF_INET6)"));
    const int one = 1;
    const int v6only = at.is_wildcard() && dual_stack_wildcard ? 0 : 1;
    ::setsockopt(fd.get(), SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    ::setsockopt(fd.get(), IPPROTO_IPV6, IPV6_V6ONLY, &v6only, sizeof v6only);
    sockaddr_in6 addr{};
    addr.sin6_family = AF_INET6;
    addr.sin6_port = htons(at.port);
    if (::inet_pton(AF_INET6, at.address.c_str(), &addr.sin6_addr) != 1) {
        throw LinkError("cannot listen on " + at.to_string() + ": not an IPv6 address");
    }
    if (::bind(fd.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
        throw LinkError(sys_error("cannot listen on " + at.to_string() +
                                  " (port in use, address not local, or IPv6 disabled): bind"));
    }
    if (::listen(fd.get(), SOMAXCONN) != 0) throw LinkError(sys_error("cannot listen on " + at.to_string()));
    return fd;
}

std::string address_of(const std::string& peer) { return peer.substr(0, peer.rfind(':')); }

}  // namespace

std::string grpc_peer_name(const sockaddr_in6& address) {
    std::array<char, INET6_ADDRSTRLEN> text{};
    const int port = ntohs(address.sin6_port);
    if (IN6_IS_ADDR_V4MAPPED(&address.sin6_addr)) {
        ::inet_ntop(AF_INET, &address.sin6_addr.s6_addr[12], text.data(), text.size());
        return fmt::format("ipv4:{}:{}", text.data(), port);
    }
    ::inet_ntop(AF_INET6, &address.sin6_addr, text.data(), text.size());
    return fmt::format("ipv6:[{}]:{}", text.data(), port);
}

struct ConnectionGuard::Impl {
    struct Connection {
        UniqueFd watch;  // dup() of the socket gRPC owns: polled for EPOLLHUP, never read
        std::string peer;
        Clock::time_point accepted;
        bool authenticated = false;
    };

    ConnectionLimits limits;
    Handoff handoff;
    UniqueFd listener;
    UniqueFd epoll;
    UniqueFd wake;  // eventfd: stop()
    std::uint16_t port = 0;

    mutable std::mutex mutex;
    std::map<int, Connection> connections;  // by the watch fd
    ConnectionGuardStats stats;
    bool stopped = false;
    std::thread thread;  // last

    void run();
    void accept_all();
    void accept_one(UniqueFd socket, const sockaddr_in6& from);
    [[nodiscard]] const char* over_cap(const std::string& peer);  // with mutex held; null: admit
    void closed(int watch_fd);
    void age_out();
    [[nodiscard]] std::uint64_t unauthenticated_of(const std::string& address) const;  // mutex held
};

ConnectionGuard::ConnectionGuard(const Endpoint& at, ConnectionLimits limits, Handoff handoff)
    : impl_(std::make_unique<Impl>()) {
    check_limits(limits);
    if (!handoff) throw LinkError("ConnectionGuard: no handoff");
    impl_->limits = limits;
    impl_->handoff = std::move(handoff);
    impl_->listener = bind_and_listen(at, limits.dual_stack_wildcard);
    sockaddr_in6 bound{};
    socklen_t length = sizeof bound;
    if (::getsockname(impl_->listener.get(), reinterpret_cast<sockaddr*>(&bound), &length) != 0) {
        throw LinkError(sys_error("getsockname on " + at.to_string()));
    }
    impl_->port = ntohs(bound.sin6_port);
    impl_->epoll = UniqueFd(::epoll_create1(EPOLL_CLOEXEC));
    impl_->wake = UniqueFd(::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK));
    if (!impl_->epoll.valid() || !impl_->wake.valid()) throw LinkError(sys_error("ConnectionGuard: epoll/eventfd"));
    for (const int fd : {impl_->listener.get(), impl_->wake.get()}) {
        epoll_event ev{};
        ev.events = EPOLLIN;
        ev.data.fd = fd;
        if (::epoll_ctl(impl_->epoll.get(), EPOLL_CTL_ADD, fd, &ev) != 0) {
            throw LinkError(sys_error("ConnectionGuard: epoll_ctl"));
        }
    }
    impl_->thread = std::thread([impl = impl_.get()] { impl->run(); });
}

ConnectionGuard::~ConnectionGuard() { stop(); }

std::uint16_t ConnectionGuard::port() const { return impl_->port; }

ConnectionGuardStats ConnectionGuard::stats() const {
    const std::lock_guard lock(impl_->mutex);
    return impl_->stats;
}

void ConnectionGuard::authenticated(const std::string& peer) {
    const std::lock_guard lock(impl_->mutex);
    for (auto& [fd, c] : impl_->connections) {
        if (c.peer == peer && !c.authenticated) {
            c.authenticated = true;
            --impl_->stats.unauthenticated;
            return;
        }
    }
}

void ConnectionGuard::stop() {
    {
        const std::lock_guard lock(impl_->mutex);
        if (impl_->stopped) return;
        impl_->stopped = true;
    }
    const std::uint64_t one = 1;
    [[maybe_unused]] const auto written = ::write(impl_->wake.get(), &one, sizeof one);
    if (impl_->thread.joinable()) impl_->thread.join();
    const std::lock_guard lock(impl_->mutex);
    impl_->connections.clear();
    impl_->stats.open = impl_->stats.unauthenticated = 0;
    impl_->listener.reset();
}

void ConnectionGuard::Impl::run() {
    std::array<epoll_event, 64> events{};
    for (;;) {
        const int n = ::epoll_wait(epoll.get(), events.data(), static_cast<int>(events.size()), 1000);
        if (n < 0 && errno != EINTR) {
            link_log().error("connection guard: epoll_wait: {}; no more connections are accepted",
                             std::strerror(errno));
            return;
        }
        for (int i = 0; i < n; ++i) {
            const int fd = events[static_cast<std::size_t>(i)].data.fd;
            if (fd == wake.get()) return;
            if (fd == listener.get()) {
                accept_all();
            } else {
                closed(fd);
            }
        }
        age_out();
    }
}

void ConnectionGuard::Impl::accept_all() {
    for (;;) {
        sockaddr_in6 from{};
        socklen_t length = sizeof from;
        UniqueFd socket(
            ::accept4(listener.get(), reinterpret_cast<sockaddr*>(&from), &length, SOCK_CLOEXEC | SOCK_NONBLOCK));
        if (!socket.valid()) {
            if (errno == EAGAIN || errno == EWOULDBLOCK) return;
            if (errno == EINTR || errno == ECONNABORTED) continue;
            // EMFILE/ENFILE/ENOBUFS: the connection stays in the backlog; try again at the next wake-up.
            link_log().warn("connection guard: accept: {}", std::strerror(errno));
            std::this_thread::sleep_for(std::chrono::milliseconds(50));
            return;
        }
        accept_one(std::move(socket), from);
    }
}

const char* ConnectionGuard::Impl::over_cap(const std::string& peer) {
    if (stats.open >= static_cast<std::uint64_t>(limits.max_connections)) {
        return worth_logging(++stats.refused_open) ? "max_connections" : "";
    }
    if (stats.unauthenticated >= static_cast<std::uint64_t>(limits.max_unauthenticated)) {
        return worth_logging(++stats.refused_unauthenticated) ? "max_unauthenticated" : "";
    }
    if (unauthenticated_of(address_of(peer)) >= static_cast<std::uint64_t>(limits.max_unauthenticated_per_address)) {
        return worth_logging(++stats.refused_per_address) ? "max_unauthenticated_per_address" : "";
    }
    return nullptr;
}

void ConnectionGuard::Impl::accept_one(UniqueFd socket, const sockaddr_in6& from) {
    const std::string peer = grpc_peer_name(from);
    UniqueFd watch(::fcntl(socket.get(), F_DUPFD_CLOEXEC, 0));
    {
        const std::lock_guard lock(mutex);
        const char* cap = watch.valid() ? over_cap(peer) : "no descriptor to watch it";
        if (cap != nullptr) {
            // Closing at once: the peer sees a reset or an end of stream before any TLS.
            if (*cap != '\0') {
                link_log().warn("refused a connection from {}: {} (open {}, unauthenticated {})", peer, cap, stats.open,
                                stats.unauthenticated);
            }
            return;
        }
        epoll_event ev{};
        ev.events = 0;  // EPOLLHUP and EPOLLERR are always reported; reading is gRPC's
        ev.data.fd = watch.get();
        if (::epoll_ctl(epoll.get(), EPOLL_CTL_ADD, watch.get(), &ev) != 0) {
            link_log().warn("connection guard: epoll_ctl: {}; connection from {} closed", std::strerror(errno), peer);
            return;
        }
        const int key = watch.get();
        connections.emplace(key, Connection{std::move(watch), peer, Clock::now(), false});
        ++stats.accepted;
        ++stats.open;
        ++stats.unauthenticated;
    }
    handoff(std::move(socket), listener.get());
}

void ConnectionGuard::Impl::closed(int watch_fd) {
    const std::lock_guard lock(mutex);
    const auto it = connections.find(watch_fd);
    if (it == connections.end()) return;
    ::epoll_ctl(epoll.get(), EPOLL_CTL_DEL, watch_fd, nullptr);
    if (!it->second.authenticated) --stats.unauthenticated;
    --stats.open;
    connections.erase(it);
}

void ConnectionGuard::Impl::age_out() {
    const auto limit = std::chrono::duration<double>(limits.unauthenticated_max_age_s);
    const auto now = Clock::now();
    const std::lock_guard lock(mutex);
    for (auto& [fd, c] : connections) {
        if (c.authenticated || now - c.accepted < limit) continue;
        // Shutting the shared socket down ends it for gRPC too; EPOLLHUP then removes it above.
        if (::shutdown(fd, SHUT_RDWR) == 0) {
            ++stats.aged_out;
            link_log().warn("closed the connection from {}: no session after {:.0f} s", c.peer,
                            limits.unauthenticated_max_age_s);
        }
        c.accepted = Clock::time_point::max();  // once
    }
}

std::uint64_t ConnectionGuard::Impl::unauthenticated_of(const std::string& address) const {
    std::uint64_t n = 0;
    for (const auto& [fd, c] : connections) n += !c.authenticated && address_of(c.peer) == address ? 1 : 0;
    return n;
}

}  // namespace mogao
