// SPDX-License-Identifier: Apache-2.0
// Certificate revocation for the link: the farm CA's certificate revocation list (CRL, X.509 v2,
// RFC 5280 section 5), kept as `crl.pem` beside `ca.pem` and written by `mogao-farm pki revoke`.
// The farm refuses a session whose appliance certificate's serial number is listed, and ends a
// session that is open when its certificate gets listed (the list is re-read when the file
// changes, without a restart). Matching is by serial number, which the CA makes unique (159
// random bits, pki.cpp); a CRL not signed by the farm CA is refused.
//
// Errors: LinkError naming the file and the reason (unreadable, not a PEM CRL, wrong issuer, bad
// signature). A watcher that fails to re-read a changed file keeps the last good list and logs
// why; only the first load may throw.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace mogao {

struct RevokedCert {
    std::string serial_hex;     // upper-case hexadecimal, no leading zeros (OpenSSL's BN_bn2hex)
    std::int64_t revoked_at_s;  // revocationDate, seconds since the Unix epoch
};

struct RevocationList {
    std::vector<RevokedCert> revoked;
    std::int64_t this_update_s = 0;
    std::int64_t next_update_s = 0;  // 0: the CRL has no nextUpdate
};

// Parses `crl_pem` and checks it was issued and signed by the CA in `ca_pem`. `source` names the
// file in messages. Throws LinkError.
[[nodiscard]] RevocationList parse_crl(const std::string& crl_pem, const std::string& ca_pem,
                                       const std::string& source);

// The serial number of a PEM certificate, as in RevokedCert::serial_hex; "" if it does not parse.
[[nodiscard]] std::string cert_serial_hex(const std::string& cert_pem);

[[nodiscard]] bool is_revoked(const RevocationList& list, const std::string& serial_hex);

// A CRL file that may change while the farm runs. Thread-safe.
class RevocationWatcher {
public:
    // Loads `path` (throws LinkError if it cannot). `recheck` bounds how often the file's identity
    // (inode, size, mtime) is looked at.
    RevocationWatcher(std::filesystem::path path, std::string ca_pem,
                      std::chrono::milliseconds recheck = std::chrono::milliseconds(1000));

    // Re-reads the file if it changed (at most once per `recheck`), then: is this serial listed?
    [[nodiscard]] bool revoked(const std::string& serial_hex);
    // Increments each time a changed file was loaded; sessions compare it to re-check themselves.
    [[nodiscard]] std::uint64_t generation();
    // nextUpdate of the list in force (seconds since the Unix epoch; 0: it has none).
    [[nodiscard]] std::int64_t next_update_s();
    [[nodiscard]] const std::filesystem::path& path() const { return path_; }

private:
    struct FileId {
        ino_t inode = 0;
        off_t size = 0;
        std::int64_t mtime_ns = 0;
        bool operator==(const FileId&) const = default;
    };
    void refresh_locked();

    std::filesystem::path path_;
    std::string ca_pem_;
    std::chrono::milliseconds recheck_;
    std::mutex mutex_;
    RevocationList list_;
    FileId id_;
    std::chrono::steady_clock::time_point checked_;
    std::uint64_t generation_ = 0;
};

}  // namespace mogao
