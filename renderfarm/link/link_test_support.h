// SPDX-License-Identifier: Apache-2.0
// Test helpers for the link (not installed, linked by the tests only): an in-memory PKI with the
// bad certificates the security tests need, a renderer-free frame source that encodes the request
// it answers into the pixels (real TurboJPEG), raw gRPC channels that bypass LinkClient, and waits
// that poll a condition (they bound a hang; they never assert on speed).
#pragma once

#include <grpcpp/grpcpp.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "renderfarm/link/link_client.h"
#include "renderfarm/link/link_server.h"
#include "renderfarm/link/mogao_link.grpc.pb.h"
#include "renderfarm/link/pki.h"

namespace mogao::testing {

// `mogao-farm pki ARGS...` in this process (run_pki_command): its exit status.
int run_pki(std::vector<std::string> args);

// Certificates made once per test process (EC P-256, a few ms).
struct TestPki {
    PemPair ca;                // the farm CA
    PemPair farm;              // CN farm-test, SANs ::1 and 127.0.0.1
    PemPair museum1, museum2;  // appliances
    PemPair expired;           // appliance "museum-old", expired yesterday
    PemPair foreign_ca;        // another CA
    PemPair foreign_museum1;   // "museum-1" issued by the other CA

    [[nodiscard]] static const TestPki& get();
    [[nodiscard]] TlsMaterial farm_tls() const { return {ca.cert_pem, farm.cert_pem, farm.key_pem}; }
    [[nodiscard]] TlsMaterial appliance_tls(const PemPair& who) const {
        return {ca.cert_pem, who.cert_pem, who.key_pem};
    }
};

// A request the synthetic renderer accepts: pinhole, width x height, resolution scale 1.
[[nodiscard]] ViewRequest test_request(double yaw_deg = 0.0, int width = 128, int height = 64);

// seed == kPoisonSeed makes the synthetic renderer throw (a renderer failure for one request).
inline constexpr std::uint64_t kPoisonSeed = 0xDEAD;

// Encodes the request id (64 bits) and the yaw in centidegrees (32 bits) as black/white 8x8
// blocks in the top-left 128x48 pixels of a render_size(request) image (JPEG-proof: blocks align
// with the DCT blocks), the rest a grey ramp. Needs at least 128x48, else throws.
class SyntheticRenderer {
public:
    RenderedFrame operator()(const ViewRequest& request);  // thread-safe
    [[nodiscard]] FrameRenderer function() {
        return [this](const ViewRequest& r) { return (*this)(r); };
    }

    // Releases at scope exit. Declare it after the LinkServer so that a failed assertion releases
    // the renderer before ~LinkServer waits for the renderer call in progress.
    class [[nodiscard]] Hold {
    public:
        explicit Hold(SyntheticRenderer& r) : renderer_(r) {}
        ~Hold() { renderer_.release(); }
        Hold(const Hold&) = delete;
        Hold& operator=(const Hold&) = delete;

    private:
        SyntheticRenderer& renderer_;
    };
    Hold hold();                                      // later calls block until release() or the Hold ends
    void release();                                   // lets every blocked and later call through
    void set_delay(std::chrono::microseconds delay);  // each call sleeps this long (a slow farm)
    [[nodiscard]] int blocked() const;                // calls waiting in hold()
    [[nodiscard]] std::vector<std::uint64_t> rendered_ids() const;  // request ids, call order

private:
    mutable std::mutex mutex_;
    std::condition_variable cv_;
    bool held_ = false;
    int blocked_ = 0;
    std::chrono::microseconds delay_{0};
    std::vector<std::uint64_t> ids_;
};

// A synthetic renderer that also records, for each request it renders, the certificate name of
// the request's session (LinkServer::appliance_of): which appliance the farm believes it serves.
// attach() the server once it is constructed (the renderer is handed to its constructor).
class SessionNameRecorder {
public:
    [[nodiscard]] FrameRenderer function();
    void attach(const LinkServer& server) { server_.store(&server); }
    [[nodiscard]] std::vector<std::string> names() const;
    [[nodiscard]] std::size_t count(const std::string& name) const;

private:
    SyntheticRenderer synthetic_;
    std::atomic<const LinkServer*> server_{nullptr};
    mutable std::mutex mutex_;
    std::vector<std::string> names_;
};

struct Mark {
    std::uint64_t request_id = 0;
    std::int32_t yaw_centideg = 0;
};
// Reads the mark back from a synthetic frame; nullopt when the JPEG does not decode or is too small.
[[nodiscard]] std::optional<Mark> read_mark(const std::vector<std::uint8_t>& jpeg);

// True when an IPv6 TCP socket can bind [::1] (tests GTEST_SKIP otherwise).
[[nodiscard]] bool ipv6_loopback_available();

// Polls `done` every few milliseconds until it is true or `limit` passes; returns done().
bool wait_until(const std::function<bool()>& done, std::chrono::milliseconds limit = std::chrono::seconds(30));

[[nodiscard]] LinkServerOptions test_server_options(const std::string& listen = "[::1]:0");
[[nodiscard]] LinkClientOptions test_client_options(std::uint16_t port, const PemPair& who);

// A TLS channel to [host]:port that bypasses LinkClient (private subchannel pool).
[[nodiscard]] std::shared_ptr<grpc::Channel> tls_channel(const std::string& target, const TlsMaterial& tls);

// Opens a raw session, sends one valid request, reads once. `got_frame` tells whether a frame came.
struct RawOutcome {
    bool got_frame = false;
    grpc::Status status;
};
[[nodiscard]] RawOutcome raw_session_once(const std::shared_ptr<grpc::Channel>& channel);

// A temporary folder removed with its contents at scope exit.
class TempDir {
public:
    TempDir();
    ~TempDir();
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    [[nodiscard]] const std::filesystem::path& path() const { return path_; }

private:
    std::filesystem::path path_;
};

}  // namespace mogao::testing
