// SPDX-License-Identifier: Apache-2.0
// The farm's certificate authority for the link's mutual TLS (OpenSSL 3). One CA per farm signs
// the farm's server certificate (extendedKeyUsage serverAuth, IP/DNS SANs) and one client
// certificate per appliance (clientAuth); the farm admits any appliance certificate that chains to
// it (optionally narrowed by LinkServerOptions::allowed_appliances). Keys: EC P-256 by default
// (RSA-3072 on request), unencrypted PKCS#8 protected by file mode 0600. See docs/link.md.
//
// Files in the PKI folder (every file mode 0600, the folder 0700 when created here):
//   ca.pem, ca.key                          farm CA (10 years by default)
//   farm-<name>.pem, farm-<name>.key        farm server certificate (825 days by default)
//   appliance-<name>.pem, appliance-<name>.key  appliance client certificate (365 days by default)
//   appliance-<name>.previous.pem           the certificate `pki renew-appliance` replaced
//   crl.pem                                 revocation list signed by the CA (revocation.h)
// That folder is the CA's workspace and holds ca.key: keep it offline. The farm serves from a
// folder made by `pki export-farm` (ca.pem, crl.pem, farm-<name>.pem/.key, never ca.key) and
// refuses a folder that holds ca.key (load_farm_tls); appliances get ca.pem and their own pair.
// Names: 1..64 of [A-Za-z0-9._-], not starting with '.' or '-'.
//
// Errors: PkiError (a std::runtime_error) naming the file or the field and the reason. Existing
// files are never overwritten unless `force` (then replaced atomically via a temporary + rename).
#pragma once

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "renderfarm/link/revocation.h"
#include "renderfarm/link/tls_material.h"

namespace mogao {

struct PkiError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

enum class KeyAlgorithm { ec_p256, rsa_3072 };
enum class CertRole { ca, farm, appliance };

struct PemPair {
    std::string cert_pem;
    std::string key_pem;
};

inline constexpr std::int64_t kSecondsPerDay = 86'400;

struct CertSpec {
    CertRole role = CertRole::appliance;
    std::string common_name;
    // Farm only: IPv6 (or IPv4) literals become IP SANs, anything else a DNS SAN (the common name
    // is always added as a DNS SAN). The appliance checks the farm's address against the IP SANs.
    std::vector<std::string> sans;
    // Validity starts at now + not_before_offset_s (back-dated 5 minutes for clock skew between
    // farm and appliances) and lasts lifetime_s. Negative values make expired certificates for tests.
    std::int64_t not_before_offset_s = -300;
    std::int64_t lifetime_s = 365 * kSecondsPerDay;
    KeyAlgorithm key = KeyAlgorithm::ec_p256;
};

// In memory: a self-signed CA (role must be ca), or a certificate signed by `ca`.
[[nodiscard]] PemPair make_ca(const CertSpec& spec);
[[nodiscard]] PemPair issue_cert(const PemPair& ca, const CertSpec& spec);

// In memory: a CRL (X.509 v2, RFC 5280 section 5) signed by `ca` listing `revoked` in serial
// order, thisUpdate now, nextUpdate in `lifetime_s`.
[[nodiscard]] std::string make_crl(const PemPair& ca, const std::vector<RevokedCert>& revoked, std::int64_t lifetime_s);

// File names inside a PKI folder.
[[nodiscard]] std::filesystem::path ca_cert_path(const std::filesystem::path& dir);
[[nodiscard]] std::filesystem::path ca_key_path(const std::filesystem::path& dir);
[[nodiscard]] std::filesystem::path farm_cert_path(const std::filesystem::path& dir, const std::string& name);
[[nodiscard]] std::filesystem::path farm_key_path(const std::filesystem::path& dir, const std::string& name);
[[nodiscard]] std::filesystem::path appliance_cert_path(const std::filesystem::path& dir, const std::string& name);
[[nodiscard]] std::filesystem::path appliance_key_path(const std::filesystem::path& dir, const std::string& name);
[[nodiscard]] std::filesystem::path previous_appliance_cert_path(const std::filesystem::path& dir,
                                                                 const std::string& name);
[[nodiscard]] std::filesystem::path crl_path(const std::filesystem::path& dir);

// "" when `name` is a valid certificate/file name, else why not.
[[nodiscard]] std::string check_pki_name(const std::string& name);

// The commands of `mogao-farm pki`. Return the files written.
std::vector<std::filesystem::path> pki_init_ca(const std::filesystem::path& dir, const std::string& name, int days,
                                               KeyAlgorithm key, bool force);
std::vector<std::filesystem::path> pki_issue_farm(const std::filesystem::path& dir, const std::string& name,
                                                  const std::vector<std::string>& sans, int days, bool force);
std::vector<std::filesystem::path> pki_issue_appliance(const std::filesystem::path& dir, const std::string& name,
                                                       int days, bool force);

// Renewal policy: a certificate is re-signed for the key it already has (no new key pair to carry
// to the appliance) only when that key is as strong as what issue-appliance makes today: EC or
// RSA with at least 128-bit security (NIST SP 800-57 Part 1 Rev. 5, Table 2: P-256 and RSA-3072
// give 128; RSA-2048 gives 112 and is refused), as OpenSSL's EVP_PKEY_get_security_bits rates it.
inline constexpr int kMinRenewalSecurityBits = 128;

// In memory: a new appliance certificate for the public key of `old_cert_pem`, signed by `ca`,
// with the old subject (and subjectAltName, if any), a new serial number and a new validity
// (now - 5 min, lasting lifetime_s). Refuses with PkiError, naming the reason, a certificate that
// `ca` did not issue (issuer and signature), that is not an appliance (clientAuth, not a CA)
// certificate, whose serial number is in `revoked`, or whose key the policy above refuses. An
// expired certificate may be renewed (its key did not change).
[[nodiscard]] std::string renew_appliance_cert(const PemPair& ca, const std::string& old_cert_pem,
                                               std::int64_t lifetime_s, const std::vector<RevokedCert>& revoked);

// `pki renew-appliance`: renews dir/appliance-<name>.pem (renew_appliance_cert, checked against
// dir/crl.pem when present) for `days`, replacing it atomically; the replaced certificate is kept
// as appliance-<name>.previous.pem (`pki revoke --name` revokes it too). The key file is neither
// read nor changed. Returns both paths.
std::vector<std::filesystem::path> pki_renew_appliance(const std::filesystem::path& dir, const std::string& name,
                                                       int days);

// `pki revoke`: adds `cert`'s serial number to dir/crl.pem (created if missing), re-signed and valid
// for `days`; revoking twice is not an error. `pki crl`: re-issues dir/crl.pem with the same
// entries and a fresh nextUpdate. Both return crl.pem.
std::vector<std::filesystem::path> pki_revoke(const std::filesystem::path& dir, const std::filesystem::path& cert,
                                              int days);
std::vector<std::filesystem::path> pki_refresh_crl(const std::filesystem::path& dir, int days);
// `pki export-farm`: copies what farm `name` serves with into `to` (created 0700): ca.pem,
// farm-<name>.pem, farm-<name>.key and crl.pem when there is one. Never ca.key.
std::vector<std::filesystem::path> pki_export_farm(const std::filesystem::path& dir, const std::string& name,
                                                   const std::filesystem::path& to, bool force);

// What each side loads to start (throws LinkError naming the missing file). load_farm_tls also
// refuses a folder holding ca.key: the CA's key must not sit on a networked farm.
[[nodiscard]] TlsMaterial load_farm_tls(const std::filesystem::path& dir, const std::string& name);
[[nodiscard]] TlsMaterial load_appliance_tls(const std::filesystem::path& dir, const std::string& name);

// Writes `content` to a new file with mode 0600 (O_CREAT|O_EXCL|O_CLOEXEC, then fchmod so that the
// umask cannot change it), fsync'd. Refuses an existing file unless `force`.
void write_private_file(const std::filesystem::path& path, const std::string& content, bool force);

// `mogao-farm pki <init-ca|issue-farm|issue-appliance|renew-appliance|revoke|crl|export-farm> ...`: argv[0] is the word
// "pki" (or any program name), the subcommand follows. Returns 0 on success, 1 when the PKI operation failed (logged),
// 2 for a bad command line (CLI11's message on stderr). Never throws.
int run_pki_command(int argc, char** argv);

}  // namespace mogao
