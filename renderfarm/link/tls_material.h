// SPDX-License-Identifier: Apache-2.0
// The PEM texts one side of the link needs for mutual TLS, and checks that turn a misconfigured
// appliance or farm into one clear message at start-up instead of an opaque handshake failure.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace mogao {

struct TlsMaterial {
    std::string ca_pem;    // the farm CA: the peer's certificate must chain to it
    std::string cert_pem;  // our certificate (issued by the farm CA)
    std::string key_pem;   // our private key (PKCS#8 or traditional PEM)
};

struct TlsFilePaths {
    std::filesystem::path ca, cert, key;
    [[nodiscard]] bool empty() const { return cert.empty(); }
};

// Reads a whole PEM file (at most 1 MiB). Throws LinkError naming the path and the reason.
[[nodiscard]] std::string read_pem_file(const std::filesystem::path& path);

// Reads the three files. Throws LinkError (see read_pem_file).
[[nodiscard]] TlsMaterial load_tls_files(const std::filesystem::path& ca, const std::filesystem::path& cert,
                                         const std::filesystem::path& key);

struct TlsCheck {
    std::string error;                  // non-empty: unusable (unparsable PEM, key does not match cert)
    std::vector<std::string> warnings;  // usable but the peer will likely refuse: expired, not yet
                                        // valid, not issued by ca_pem
};

// Parses the material with OpenSSL. `who` prefixes every message ("farm", "appliance").
[[nodiscard]] TlsCheck check_tls_material(const TlsMaterial& material, const std::string& who);

}  // namespace mogao
