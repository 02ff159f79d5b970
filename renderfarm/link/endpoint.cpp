// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/link/endpoint.h"

#include <arpa/inet.h>

#include <charconv>

namespace mogao {

std::optional<Endpoint> parse_endpoint(std::string_view text, std::string* error) {
    const auto fail = [&](std::string_view why) -> std::optional<Endpoint> {
        if (error) *error = "endpoint '" + std::string(text) + "': " + std::string(why);
        return std::nullopt;
    };
    const auto close = text.rfind(']');
    if (text.empty() || text.front() != '[' || close == std::string_view::npos) {
        return fail("expected [IPv6-address]:port, e.g. [::1]:7443");
    }
    const std::string address(text.substr(1, close - 1));
    if (address.find('%') != std::string::npos)
        return fail("zone ids (%iface) are not supported; use a global or ULA address");
    in6_addr binary{};
    if (inet_pton(AF_INET6, address.c_str(), &binary) != 1) return fail("'" + address + "' is not an IPv6 address");
    const std::string_view rest = text.substr(close + 1);
    if (rest.size() < 2 || rest.front() != ':') return fail("missing :port after ]");
    const std::string_view digits = rest.substr(1);
    unsigned port = 0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), port);
    if (ec != std::errc{} || end != digits.data() + digits.size() || port > 65535) {
        return fail("port must be a number in [0, 65535]");
    }
    char normal[INET6_ADDRSTRLEN] = {};
    inet_ntop(AF_INET6, &binary, normal, sizeof normal);
    return Endpoint{normal, static_cast<std::uint16_t>(port)};
}

}  // namespace mogao
