// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/link/endpoint.h"

#include <gtest/gtest.h>

namespace mogao {
namespace {

TEST(Endpoint, ParsesAndNormalisesIpv6Literals) {
    const auto loopback = parse_endpoint("[::1]:7443");
    ASSERT_TRUE(loopback);
    EXPECT_EQ(loopback->address, "::1");
    EXPECT_EQ(loopback->port, 7443);
    EXPECT_EQ(loopback->to_string(), "[::1]:7443");
    EXPECT_EQ(loopback->grpc_target(), "ipv6:[::1]:7443");
    EXPECT_FALSE(loopback->is_wildcard());

    const auto wildcard = parse_endpoint(kDefaultListenEndpoint);
    ASSERT_TRUE(wildcard);
    EXPECT_TRUE(wildcard->is_wildcard());
    EXPECT_EQ(wildcard->port, kDefaultLinkPort);

    const auto global = parse_endpoint("[2001:DB8:0::5]:0");
    ASSERT_TRUE(global);
    EXPECT_EQ(global->address, "2001:db8::5");
    EXPECT_EQ(global->port, 0);
}

TEST(Endpoint, RefusesWhatIsNotBracketedIpv6WithAPort) {
    for (const char* bad : {"", "::1:7443", "[::1]", "[::1]:", "[::1]7443", "[::1]:70000", "[::1]:-1", "[::1]:12a",
                            "[127.0.0.1]:7443", "[farm-1]:7443", "[fe80::1%eth0]:7443", "[::1]:7443x", "[]:7443"}) {
        std::string error;
        EXPECT_FALSE(parse_endpoint(bad, &error)) << bad;
        EXPECT_NE(error.find(std::string("'") + bad + "'"), std::string::npos)
            << "error should quote the text: " << error;
    }
}

TEST(Endpoint, ErrorSaysWhatIsWrong) {
    std::string error;
    ASSERT_FALSE(parse_endpoint("[::1]:99999", &error));
    EXPECT_NE(error.find("port"), std::string::npos) << error;
    ASSERT_FALSE(parse_endpoint("[fe80::1%eth0]:1", &error));
    EXPECT_NE(error.find("zone"), std::string::npos) << error;
    ASSERT_FALSE(parse_endpoint("[1.2.3.4]:1", &error));
    EXPECT_NE(error.find("not an IPv6 address"), std::string::npos) << error;
}

}  // namespace
}  // namespace mogao
