// SPDX-License-Identifier: Apache-2.0
// IPv6 endpoints written "[address]:port", e.g. "[::]:7443", "[::1]:7443", "[2001:db8::5]:7443".
//
// Only literal IPv6 addresses are accepted (no host names: the farm's certificate is issued for
// its addresses, and no DNS is needed on a museum LAN); zone ids ("%eth0") are not supported, use a
// global or ULA address. The address is normalised with inet_ntop ("0:0::1" -> "::1").
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace mogao {

inline constexpr std::uint16_t kDefaultLinkPort = 7443;
inline constexpr std::string_view kDefaultListenEndpoint = "[::]:7443";

struct Endpoint {
    std::string address;     // IPv6 literal without brackets, normalised
    std::uint16_t port = 0;  // 0 only for a server: the kernel picks a free port

    [[nodiscard]] std::string to_string() const { return "[" + address + "]:" + std::to_string(port); }
    // gRPC client target that skips name resolution: "ipv6:[address]:port".
    [[nodiscard]] std::string grpc_target() const { return "ipv6:" + to_string(); }
    [[nodiscard]] bool is_wildcard() const { return address == "::"; }
};

// Parses "[address]:port". On failure returns nullopt and sets *error (if given) to a message that
// quotes the text and says what was expected.
[[nodiscard]] std::optional<Endpoint> parse_endpoint(std::string_view text, std::string* error = nullptr);

}  // namespace mogao
