// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/link/link_test_support.h"

#include <algorithm>

#include <netinet/in.h>
#include <sys/socket.h>

#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <thread>

#include "common/jpeg_codec.h"
#include "common/unique_fd.h"
#include "renderfarm/link/wire_convert.h"

namespace mogao::testing {

int run_pki(std::vector<std::string> args) {
    args.insert(args.begin(), "pki");
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    return run_pki_command(static_cast<int>(argv.size()), argv.data());
}
namespace {

constexpr int kBlock = 8;
constexpr int kBlocksPerRow = 16;
constexpr int kMarkBits = 96;
constexpr int kMarkWidth = kBlock * kBlocksPerRow;                                       // 128
constexpr int kMarkHeight = kBlock * ((kMarkBits + kBlocksPerRow - 1) / kBlocksPerRow);  // 48

bool mark_bit(std::uint64_t id, std::uint32_t yaw, int bit) {
    return bit < 64 ? ((id >> bit) & 1u) != 0 : ((yaw >> (bit - 64)) & 1u) != 0;
}

}  // namespace

const TestPki& TestPki::get() {
    static const TestPki pki = [] {
        TestPki p;
        p.ca = make_ca({CertRole::ca, "mogao test CA", {}, -300, 10 * kSecondsPerDay, KeyAlgorithm::ec_p256});
        p.farm = issue_cert(
            p.ca, {CertRole::farm, "farm-test", {"::1", "127.0.0.1"}, -300, kSecondsPerDay, KeyAlgorithm::ec_p256});
        p.museum1 =
            issue_cert(p.ca, {CertRole::appliance, "museum-1", {}, -300, kSecondsPerDay, KeyAlgorithm::ec_p256});
        p.museum2 =
            issue_cert(p.ca, {CertRole::appliance, "museum-2", {}, -300, kSecondsPerDay, KeyAlgorithm::ec_p256});
        // Valid from two days ago until yesterday.
        p.expired = issue_cert(
            p.ca, {CertRole::appliance, "museum-old", {}, -2 * kSecondsPerDay, kSecondsPerDay, KeyAlgorithm::ec_p256});
        p.foreign_ca =
            make_ca({CertRole::ca, "someone else's CA", {}, -300, 10 * kSecondsPerDay, KeyAlgorithm::ec_p256});
        p.foreign_museum1 = issue_cert(
            p.foreign_ca, {CertRole::appliance, "museum-1", {}, -300, kSecondsPerDay, KeyAlgorithm::ec_p256});
        return p;
    }();
    return pki;
}

ViewRequest test_request(double yaw_deg, int width, int height) {
    ViewRequest request;
    request.pose.yaw_deg = yaw_deg;
    request.camera = PinholeCamera{60.0};
    request.size = {width, height};
    request.quality.jpeg_quality = 90;
    return request;
}

RenderedFrame SyntheticRenderer::operator()(const ViewRequest& request) {
    std::chrono::microseconds delay{0};
    {
        std::unique_lock lock(mutex_);
        ids_.push_back(request.frame_id);
        ++blocked_;
        cv_.wait(lock, [&] { return !held_; });
        --blocked_;
        delay = delay_;
    }
    if (delay.count() > 0) std::this_thread::sleep_for(delay);
    if (request.seed == kPoisonSeed) throw std::runtime_error("poisoned request (test)");
    const ImageSize size = render_size(request);
    if (size.width < kMarkWidth || size.height < kMarkHeight) {
        throw std::invalid_argument("synthetic renderer needs at least 128x48 pixels");
    }
    Rgb8Image image(size);
    for (int y = 0; y < size.height; ++y) {
        for (int x = 0; x < size.width; ++x) {
            auto* px = image.at(x, y);
            px[0] = px[1] = px[2] = static_cast<std::uint8_t>((x * 255) / size.width);
        }
    }
    const auto yaw = static_cast<std::uint32_t>(static_cast<std::int32_t>(std::lround(request.pose.yaw_deg * 100.0)));
    for (int bit = 0; bit < kMarkBits; ++bit) {
        const std::uint8_t value = mark_bit(request.frame_id, yaw, bit) ? 255 : 0;
        const int bx = (bit % kBlocksPerRow) * kBlock, by = (bit / kBlocksPerRow) * kBlock;
        for (int y = by; y < by + kBlock; ++y) {
            for (int x = bx; x < bx + kBlock; ++x) {
                auto* px = image.at(x, y);
                px[0] = px[1] = px[2] = value;
            }
        }
    }
    thread_local JpegEncoder encoder;  // one TurboJPEG handle per render thread
    RenderedFrame frame;
    frame.size = size;
    frame.jpeg = encoder.encode(image, request.quality.jpeg_quality, Subsampling::yuv420);
    return frame;
}

SyntheticRenderer::Hold SyntheticRenderer::hold() {
    const std::lock_guard lock(mutex_);
    held_ = true;
    return Hold(*this);
}

void SyntheticRenderer::release() {
    {
        const std::lock_guard lock(mutex_);
        held_ = false;
    }
    cv_.notify_all();
}

void SyntheticRenderer::set_delay(std::chrono::microseconds delay) {
    const std::lock_guard lock(mutex_);
    delay_ = delay;
}

int SyntheticRenderer::blocked() const {
    const std::lock_guard lock(mutex_);
    return blocked_;
}

std::vector<std::uint64_t> SyntheticRenderer::rendered_ids() const {
    const std::lock_guard lock(mutex_);
    return ids_;
}

std::optional<Mark> read_mark(const std::vector<std::uint8_t>& jpeg) {
    Rgb8Image image;
    try {
        JpegDecoder decoder;
        image = decoder.decode(jpeg);
    } catch (const std::exception&) {
        return std::nullopt;
    }
    if (image.size.width < kMarkWidth || image.size.height < kMarkHeight) return std::nullopt;
    Mark mark;
    std::uint32_t yaw = 0;
    for (int bit = 0; bit < kMarkBits; ++bit) {
        const int cx = (bit % kBlocksPerRow) * kBlock + kBlock / 2, cy = (bit / kBlocksPerRow) * kBlock + kBlock / 2;
        if (image.at(cx, cy)[1] < 128) continue;
        if (bit < 64) {
            mark.request_id |= std::uint64_t{1} << bit;
        } else {
            yaw |= std::uint32_t{1} << (bit - 64);
        }
    }
    mark.yaw_centideg = static_cast<std::int32_t>(yaw);
    return mark;
}

bool ipv6_loopback_available() {
    const UniqueFd fd(::socket(AF_INET6, SOCK_STREAM | SOCK_CLOEXEC, 0));
    if (!fd.valid()) return false;
    sockaddr_in6 addr{};
    addr.sin6_family = AF_INET6;
    addr.sin6_addr = in6addr_loopback;
    return ::bind(fd.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof addr) == 0;
}

bool wait_until(const std::function<bool()>& done, std::chrono::milliseconds limit) {
    const auto end = std::chrono::steady_clock::now() + limit;
    while (!done()) {
        if (std::chrono::steady_clock::now() > end) return done();
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return true;
}

LinkServerOptions test_server_options(const std::string& listen) {
    LinkServerOptions options;
    options.listen = listen;
    options.tls = TestPki::get().farm_tls();
    return options;
}

LinkClientOptions test_client_options(std::uint16_t port, const PemPair& who) {
    LinkClientOptions options;
    options.endpoint = "[::1]:" + std::to_string(port);
    options.tls = TestPki::get().appliance_tls(who);
    // Short waits keep the reconnect tests quick; the doubling and the cap are what is exercised.
    options.initial_backoff = std::chrono::milliseconds(20);
    options.max_backoff = std::chrono::milliseconds(200);
    return options;
}

std::shared_ptr<grpc::Channel> tls_channel(const std::string& target, const TlsMaterial& tls) {
    grpc::SslCredentialsOptions ssl;
    ssl.pem_root_certs = tls.ca_pem;
    ssl.pem_private_key = tls.key_pem;
    ssl.pem_cert_chain = tls.cert_pem;
    grpc::ChannelArguments args;
    args.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);
    return grpc::CreateCustomChannel(target, grpc::SslCredentials(ssl), args);
}

FrameRenderer SessionNameRecorder::function() {
    return [this](const ViewRequest& view) {
        const LinkServer* server = server_.load();
        std::string name = server != nullptr ? server->appliance_of(view.session) : std::string("(not attached)");
        {
            const std::lock_guard lock(mutex_);
            names_.push_back(std::move(name));
        }
        return synthetic_(view);
    };
}

std::vector<std::string> SessionNameRecorder::names() const {
    const std::lock_guard lock(mutex_);
    return names_;
}

std::size_t SessionNameRecorder::count(const std::string& name) const {
    const std::lock_guard lock(mutex_);
    return static_cast<std::size_t>(std::count(names_.begin(), names_.end(), name));
}

RawOutcome raw_session_once(const std::shared_ptr<grpc::Channel>& channel) {
    auto stub = link::v1::Tour::NewStub(channel);
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));  // hang guard only
    auto stream = stub->Session(&ctx);
    ViewRequest request = test_request();
    request.frame_id = 1;
    link::v1::ViewRequestMsg msg;
    view_to_msg(request, msg);
    // No WritesDone: a half-close ends the session on the farm (frames not yet sent are dropped).
    stream->Write(msg);
    link::v1::FrameMsg frame;
    RawOutcome outcome;
    outcome.got_frame = stream->Read(&frame);
    if (outcome.got_frame) ctx.TryCancel();
    outcome.status = stream->Finish();
    return outcome;
}

TempDir::TempDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "mogao-link-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
}

TempDir::~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
}

}  // namespace mogao::testing
