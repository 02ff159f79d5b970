// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/link/pki.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <openssl/ec.h>
#include <openssl/err.h>
#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>

#include <fmt/format.h>

#include "common/link_types.h"
#include "common/unique_fd.h"
#include "renderfarm/link/openssl_util.h"

namespace mogao {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const std::string& what) {
    const std::string why = ossl::errors();
    throw PkiError(why.empty() ? what : what + " (" + why + ")");
}

ossl::Pkey make_key(KeyAlgorithm algorithm) {
    // EC P-256: small, fast handshakes, supported by every TLS 1.2/1.3 stack gRPC uses.
    ossl::Pkey key(algorithm == KeyAlgorithm::ec_p256 ? EVP_EC_gen("P-256") : EVP_RSA_gen(3072));
    if (!key) fail("key generation failed");
    return key;
}

void add_ext(X509* cert, X509V3_CTX& ctx, int nid, const char* value) {
    X509_EXTENSION* ext = X509V3_EXT_conf_nid(nullptr, &ctx, nid, value);
    if (!ext) fail(std::string("bad certificate extension ") + OBJ_nid2sn(nid) + "=" + value);
    const int ok = X509_add_ext(cert, ext, -1);
    X509_EXTENSION_free(ext);
    if (ok != 1) fail(std::string("cannot add extension ") + OBJ_nid2sn(nid));
}

void add_sans(X509* cert, const CertSpec& spec) {
    ossl::GeneralNames names(GENERAL_NAMES_new());
    if (!names) fail("out of memory");
    std::vector<std::string> entries = spec.sans;
    entries.insert(entries.begin(), spec.common_name);
    for (const auto& entry : entries) {
        ossl::GeneralName name(GENERAL_NAME_new());
        if (!name) fail("out of memory");
        in6_addr v6{};
        in_addr v4{};
        if (inet_pton(AF_INET6, entry.c_str(), &v6) == 1 || inet_pton(AF_INET, entry.c_str(), &v4) == 1) {
            ossl::OctetString ip(a2i_IPADDRESS(entry.c_str()));
            if (!ip) fail("bad IP SAN '" + entry + "'");
            GENERAL_NAME_set0_value(name.get(), GEN_IPADD, ip.release());
        } else {
            if (!check_pki_name(entry).empty() || entry.find('.') == 0) {
                throw PkiError("SAN '" + entry + "' is neither an IP address nor a DNS name");
            }
            ASN1_IA5STRING* dns = ASN1_IA5STRING_new();
            if (!dns || ASN1_STRING_set(dns, entry.data(), static_cast<int>(entry.size())) != 1) {
                ASN1_IA5STRING_free(dns);
                fail("out of memory");
            }
            GENERAL_NAME_set0_value(name.get(), GEN_DNS, dns);
        }
        if (sk_GENERAL_NAME_push(names.get(), name.get()) == 0) fail("out of memory");
        static_cast<void>(name.release());  // owned by `names` now
    }
    if (X509_add1_ext_i2d(cert, NID_subject_alt_name, names.get(), 0, X509V3_ADD_DEFAULT) != 1) {
        fail("cannot add subjectAltName");
    }
}

// The subject: O=mogao, CN=spec.common_name; or, renewing, the old certificate's, verbatim.
void set_subject(X509* cert, const CertSpec& spec, X509* renewed) {
    if (renewed) {
        if (X509_set_subject_name(cert, X509_get_subject_name(renewed)) != 1) fail("cannot copy the subject");
        return;
    }
    X509_NAME* subject = X509_get_subject_name(cert);
    const auto* org = reinterpret_cast<const unsigned char*>("mogao");
    const auto* cn = reinterpret_cast<const unsigned char*>(spec.common_name.c_str());
    if (X509_NAME_add_entry_by_txt(subject, "O", MBSTRING_UTF8, org, -1, -1, 0) != 1 ||
        X509_NAME_add_entry_by_txt(subject, "CN", MBSTRING_UTF8, cn, -1, -1, 0) != 1) {
        fail("bad common name '" + spec.common_name + "'");
    }
}

// basicConstraints, keyUsage, extendedKeyUsage and the SANs of the role. Renewing, the old
// certificate's subjectAltName is copied as it is (an appliance's has none today).
void add_role_extensions(X509* cert, X509V3_CTX& ctx, const CertSpec& spec, X509* renewed) {
    switch (spec.role) {
        case CertRole::ca:
            add_ext(cert, ctx, NID_basic_constraints, "critical,CA:TRUE,pathlen:0");
            add_ext(cert, ctx, NID_key_usage, "critical,keyCertSign,cRLSign");
            return;
        case CertRole::farm:
            add_ext(cert, ctx, NID_basic_constraints, "critical,CA:FALSE");
            add_ext(cert, ctx, NID_key_usage, "critical,digitalSignature,keyEncipherment");
            // serverAuth only: a farm certificate cannot pose as an appliance, nor the reverse.
            add_ext(cert, ctx, NID_ext_key_usage, "serverAuth");
            add_sans(cert, spec);
            return;
        case CertRole::appliance:
            add_ext(cert, ctx, NID_basic_constraints, "critical,CA:FALSE");
            add_ext(cert, ctx, NID_key_usage, "critical,digitalSignature,keyEncipherment");
            add_ext(cert, ctx, NID_ext_key_usage, "clientAuth");
            if (!renewed) return;
            if (const int at = X509_get_ext_by_NID(renewed, NID_subject_alt_name, -1); at >= 0) {
                if (X509_add_ext(cert, X509_get_ext(renewed, at), -1) != 1) fail("cannot copy subjectAltName");
            }
            return;
    }
}

// Builds and signs one certificate. `issuer`/`issuer_key` null: self-signed with `key` (then
// `key` must hold the private key; otherwise its public half is enough). `renewed`: the
// certificate being renewed, whose subject and SANs are kept.
ossl::Cert build_cert(const CertSpec& spec, EVP_PKEY* key, X509* issuer, EVP_PKEY* issuer_key,
                      X509* renewed = nullptr) {
    if (auto why = check_pki_name(spec.common_name); !why.empty() && spec.role != CertRole::ca) throw PkiError(why);
    if (spec.common_name.empty() || spec.common_name.size() > 64)
        throw PkiError("common name must be 1..64 characters");
    if (spec.lifetime_s <= 0) throw PkiError("certificate lifetime must be positive");
    ossl::Cert cert(X509_new());
    if (!cert || X509_set_version(cert.get(), X509_VERSION_3) != 1) fail("out of memory");
    // 159 random bits: positive, unique with overwhelming probability, within RFC 5280's 20 octets.
    ossl::Bignum serial(BN_new());
    if (!serial || BN_rand(serial.get(), 159, BN_RAND_TOP_ANY, BN_RAND_BOTTOM_ANY) != 1 ||
        !BN_to_ASN1_INTEGER(serial.get(), X509_get_serialNumber(cert.get()))) {
        fail("cannot make a serial number");
    }
    if (!X509_gmtime_adj(X509_getm_notBefore(cert.get()), spec.not_before_offset_s) ||
        !X509_gmtime_adj(X509_getm_notAfter(cert.get()), spec.not_before_offset_s + spec.lifetime_s)) {
        fail("cannot set the validity period");
    }
    set_subject(cert.get(), spec, renewed);
    X509_NAME* subject = X509_get_subject_name(cert.get());
    if (X509_set_issuer_name(cert.get(), issuer ? X509_get_subject_name(issuer) : subject) != 1 ||
        X509_set_pubkey(cert.get(), key) != 1) {
        fail("cannot set issuer or public key");
    }
    X509V3_CTX ctx;
    X509V3_set_ctx_nodb(&ctx);
    X509V3_set_ctx(&ctx, issuer ? issuer : cert.get(), cert.get(), nullptr, nullptr, 0);
    add_role_extensions(cert.get(), ctx, spec, renewed);
    add_ext(cert.get(), ctx, NID_subject_key_identifier, "hash");
    if (issuer) add_ext(cert.get(), ctx, NID_authority_key_identifier, "keyid:always");
    if (X509_sign(cert.get(), issuer_key ? issuer_key : key, EVP_sha256()) == 0) fail("signing failed");
    return cert;
}

void require_absent(const std::vector<fs::path>& paths, bool force) {
    if (force) return;
    for (const auto& p : paths) {
        std::error_code ec;
        if (fs::exists(fs::symlink_status(p, ec))) {
            throw PkiError("refusing to overwrite " + p.string() + " (use --force to replace it)");
        }
    }
}

void ensure_dir(const fs::path& dir) {
    std::error_code ec;
    if (fs::is_directory(dir, ec)) return;
    fs::create_directories(dir, ec);
    if (ec) throw PkiError("cannot create " + dir.string() + ": " + ec.message());
    if (::chmod(dir.c_str(), 0700) != 0)
        throw PkiError("cannot chmod 0700 " + dir.string() + ": " + std::strerror(errno));
}

PemPair load_ca_files(const fs::path& dir) {
    try {
        return {read_pem_file(ca_cert_path(dir)), read_pem_file(ca_key_path(dir))};
    } catch (const std::exception& e) {
        throw PkiError(std::string(e.what()) + " (run `pki init-ca --dir " + dir.string() + "` first)");
    }
}

std::vector<fs::path> write_pair(const fs::path& cert_path, const fs::path& key_path, const PemPair& pair, bool force) {
    require_absent({cert_path, key_path}, force);
    write_private_file(key_path, pair.key_pem, force);
    write_private_file(cert_path, pair.cert_pem, force);
    return {cert_path, key_path};
}

std::int64_t days_to_seconds(int days) {
    if (days < 1 || days > 100 * 365) throw PkiError("--days " + std::to_string(days) + " is outside [1, 36500]");
    return std::int64_t{days} * kSecondsPerDay;
}

}  // namespace

std::string check_pki_name(const std::string& name) {
    if (name.empty() || name.size() > 64) return "name '" + name + "' must be 1..64 characters";
    if (name.front() == '.' || name.front() == '-') return "name '" + name + "' must not start with '.' or '-'";
    for (const char c : name) {
        const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                        c == '_' || c == '-';
        if (!ok) return "name '" + name + "' may only use letters, digits, '.', '_' and '-'";
    }
    return {};
}

PemPair make_ca(const CertSpec& spec) {
    if (spec.role != CertRole::ca) throw PkiError("make_ca: spec.role must be CertRole::ca");
    ossl::Pkey key = make_key(spec.key);
    ossl::Cert cert = build_cert(spec, key.get(), nullptr, nullptr);
    return {ossl::cert_to_pem(cert.get()), ossl::key_to_pem(key.get())};
}

PemPair issue_cert(const PemPair& ca, const CertSpec& spec) {
    if (spec.role == CertRole::ca) throw PkiError("issue_cert: use make_ca for a CA");
    ossl::Cert ca_cert = ossl::parse_cert(ca.cert_pem);
    ossl::Pkey ca_key = ossl::parse_key(ca.key_pem);
    if (!ca_cert || !ca_key) fail("cannot parse the CA certificate or key");
    if (X509_check_private_key(ca_cert.get(), ca_key.get()) != 1) fail("the CA key does not match the CA certificate");
    ossl::Pkey key = make_key(spec.key);
    ossl::Cert cert = build_cert(spec, key.get(), ca_cert.get(), ca_key.get());
    return {ossl::cert_to_pem(cert.get()), ossl::key_to_pem(key.get())};
}

std::string make_crl(const PemPair& ca, const std::vector<RevokedCert>& revoked, std::int64_t lifetime_s) {
    if (lifetime_s <= 0) throw PkiError("revocation list lifetime must be positive");
    ossl::Cert ca_cert = ossl::parse_cert(ca.cert_pem);
    ossl::Pkey ca_key = ossl::parse_key(ca.key_pem);
    if (!ca_cert || !ca_key) fail("cannot parse the CA certificate or key");
    if (X509_check_private_key(ca_cert.get(), ca_key.get()) != 1) fail("the CA key does not match the CA certificate");
    ossl::Crl crl(X509_CRL_new());
    ossl::Time now(ASN1_TIME_adj(nullptr, std::time(nullptr), 0, 0));
    ossl::Time next(ASN1_TIME_adj(nullptr, std::time(nullptr), 0, static_cast<long>(lifetime_s)));
    if (!crl || !now || !next || X509_CRL_set_version(crl.get(), X509_CRL_VERSION_2) != 1 ||
        X509_CRL_set_issuer_name(crl.get(), X509_get_subject_name(ca_cert.get())) != 1 ||
        X509_CRL_set1_lastUpdate(crl.get(), now.get()) != 1 || X509_CRL_set1_nextUpdate(crl.get(), next.get()) != 1) {
        fail("cannot start a revocation list");
    }
    for (const auto& r : revoked) {
        ossl::Revoked entry(X509_REVOKED_new());
        BIGNUM* raw = nullptr;
        if (!entry || BN_hex2bn(&raw, r.serial_hex.c_str()) == 0) fail("bad serial number '" + r.serial_hex + "'");
        const ossl::Bignum serial(raw);
        UniquePtr<ASN1_INTEGER, &ASN1_INTEGER_free> number(BN_to_ASN1_INTEGER(serial.get(), nullptr));
        ossl::Time when(ASN1_TIME_set(nullptr, static_cast<time_t>(r.revoked_at_s)));
        if (!number || !when || X509_REVOKED_set_serialNumber(entry.get(), number.get()) != 1 ||
            X509_REVOKED_set_revocationDate(entry.get(), when.get()) != 1 ||
            X509_CRL_add0_revoked(crl.get(), entry.get()) != 1) {
            fail("cannot list serial number " + r.serial_hex);
        }
        static_cast<void>(entry.release());  // owned by the CRL now
    }
    if (X509_CRL_sort(crl.get()) != 1 || X509_CRL_sign(crl.get(), ca_key.get(), EVP_sha256()) == 0) {
        fail("cannot sign the revocation list");
    }
    return ossl::crl_to_pem(crl.get());
}

fs::path ca_cert_path(const fs::path& dir) { return dir / "ca.pem"; }
fs::path ca_key_path(const fs::path& dir) { return dir / "ca.key"; }
fs::path farm_cert_path(const fs::path& dir, const std::string& name) { return dir / ("farm-" + name + ".pem"); }
fs::path farm_key_path(const fs::path& dir, const std::string& name) { return dir / ("farm-" + name + ".key"); }
fs::path appliance_cert_path(const fs::path& dir, const std::string& name) {
    return dir / ("appliance-" + name + ".pem");
}
fs::path appliance_key_path(const fs::path& dir, const std::string& name) {
    return dir / ("appliance-" + name + ".key");
}
fs::path previous_appliance_cert_path(const fs::path& dir, const std::string& name) {
    return dir / ("appliance-" + name + ".previous.pem");
}
fs::path crl_path(const fs::path& dir) { return dir / "crl.pem"; }

std::vector<fs::path> pki_init_ca(const fs::path& dir, const std::string& name, int days, KeyAlgorithm key,
                                  bool force) {
    CertSpec spec{CertRole::ca, name, {}, -300, days_to_seconds(days), key};
    require_absent({ca_cert_path(dir), ca_key_path(dir)}, force);
    const PemPair ca = make_ca(spec);
    ensure_dir(dir);
    return write_pair(ca_cert_path(dir), ca_key_path(dir), ca, force);
}

std::vector<fs::path> pki_issue_farm(const fs::path& dir, const std::string& name, const std::vector<std::string>& sans,
                                     int days, bool force) {
    if (auto why = check_pki_name(name); !why.empty()) throw PkiError(why);
    const CertSpec spec{CertRole::farm, name, sans, -300, days_to_seconds(days), KeyAlgorithm::ec_p256};
    const PemPair pair = issue_cert(load_ca_files(dir), spec);
    return write_pair(farm_cert_path(dir, name), farm_key_path(dir, name), pair, force);
}

std::vector<fs::path> pki_issue_appliance(const fs::path& dir, const std::string& name, int days, bool force) {
    if (auto why = check_pki_name(name); !why.empty()) throw PkiError(why);
    const CertSpec spec{CertRole::appliance, name, {}, -300, days_to_seconds(days), KeyAlgorithm::ec_p256};
    const PemPair pair = issue_cert(load_ca_files(dir), spec);
    return write_pair(appliance_cert_path(dir, name), appliance_key_path(dir, name), pair, force);
}

namespace {

std::vector<RevokedCert> current_revocations(const fs::path& dir, const PemPair& ca) {
    std::error_code ec;
    if (!fs::exists(crl_path(dir), ec)) return {};
    try {
        return parse_crl(read_pem_file(crl_path(dir)), ca.cert_pem, crl_path(dir).string()).revoked;
    } catch (const std::exception& e) {
        throw PkiError(std::string(e.what()) + " (move it away to start a new list)");
    }
}

void write_crl(const fs::path& dir, const PemPair& ca, const std::vector<RevokedCert>& revoked, int days) {
    write_private_file(crl_path(dir), make_crl(ca, revoked, days_to_seconds(days)), true);
}

}  // namespace

std::vector<fs::path> pki_revoke(const fs::path& dir, const fs::path& cert, int days) {
    const PemPair ca = load_ca_files(dir);
    std::string serial;
    try {
        serial = cert_serial_hex(read_pem_file(cert));
    } catch (const std::exception& e) {
        throw PkiError(e.what());
    }
    if (serial.empty()) throw PkiError(cert.string() + ": not a PEM certificate");
    std::vector<RevokedCert> revoked = current_revocations(dir, ca);
    const bool listed =
        std::any_of(revoked.begin(), revoked.end(), [&](const auto& r) { return r.serial_hex == serial; });
    if (!listed) revoked.push_back({serial, static_cast<std::int64_t>(std::time(nullptr))});
    write_crl(dir, ca, revoked, days);
    return {crl_path(dir)};
}

std::vector<fs::path> pki_refresh_crl(const fs::path& dir, int days) {
    const PemPair ca = load_ca_files(dir);
    write_crl(dir, ca, current_revocations(dir, ca), days);
    return {crl_path(dir)};
}

namespace {

// "EC P-256 (128-bit security)", "RSA 2048 bits (112-bit security)".
std::string key_words(EVP_PKEY* key) {
    const int bits = EVP_PKEY_get_security_bits(key);
    if (EVP_PKEY_is_a(key, "EC")) {
        char curve[64] = {};
        std::size_t length = 0;
        if (EVP_PKEY_get_utf8_string_param(key, "group", curve, sizeof curve, &length) != 1) curve[0] = '\0';
        const char* nist = curve[0] ? EC_curve_nid2nist(OBJ_txt2nid(curve)) : nullptr;  // "P-224" for secp224r1
        return fmt::format("EC {} ({}-bit security)", nist ? nist : curve[0] ? curve : "?", bits);
    }
    return fmt::format("{} {} bits ({}-bit security)", EVP_PKEY_get0_type_name(key), EVP_PKEY_get_bits(key), bits);
}

// Why `old` may not be renewed by `ca_cert`, "" when it may (the policy in pki.h).
std::string renewal_refusal(X509* ca_cert, X509* old, const std::vector<RevokedCert>& revoked) {
    const std::string who = "certificate CN=" + ossl::subject_cn(old);
    EVP_PKEY* ca_key = X509_get0_pubkey(ca_cert);
    if (X509_check_issued(ca_cert, old) != X509_V_OK || !ca_key || X509_verify(old, ca_key) != 1) {
        ERR_clear_error();
        return who + " was not issued by this CA (" + ossl::subject_cn(ca_cert) + ")";
    }
    const std::uint32_t xku = X509_get_extended_key_usage(old);
    if (X509_check_ca(old) != 0 || (xku & XKU_SSL_CLIENT) == 0 || (xku & XKU_SSL_SERVER) != 0) {
        return who + " is not an appliance (clientAuth) certificate";
    }
    const std::string serial = ossl::integer_hex(X509_get0_serialNumber(old));
    if (std::any_of(revoked.begin(), revoked.end(), [&](const auto& r) { return r.serial_hex == serial; })) {
        return who + " (serial " + serial + ") is revoked: its key may be compromised";
    }
    EVP_PKEY* key = X509_get0_pubkey(old);
    if (!key) return who + ": its public key cannot be read";
    const bool kind_ok = EVP_PKEY_is_a(key, "EC") || EVP_PKEY_is_a(key, "RSA");
    if (!kind_ok || EVP_PKEY_get_security_bits(key) < kMinRenewalSecurityBits) {
        return who + ": its key, " + key_words(key) + ", is weaker than what issue-appliance makes (EC P-256, " +
               std::to_string(kMinRenewalSecurityBits) + "-bit security)";
    }
    return {};
}

}  // namespace

std::string renew_appliance_cert(const PemPair& ca, const std::string& old_cert_pem, std::int64_t lifetime_s,
                                 const std::vector<RevokedCert>& revoked) {
    ossl::Cert ca_cert = ossl::parse_cert(ca.cert_pem);
    ossl::Pkey ca_key = ossl::parse_key(ca.key_pem);
    if (!ca_cert || !ca_key) fail("cannot parse the CA certificate or key");
    if (X509_check_private_key(ca_cert.get(), ca_key.get()) != 1) fail("the CA key does not match the CA certificate");
    ossl::Cert old = ossl::parse_cert(old_cert_pem);
    if (!old) fail("the certificate to renew is not a PEM certificate");
    if (const std::string why = renewal_refusal(ca_cert.get(), old.get(), revoked); !why.empty()) {
        throw PkiError("refusing to renew: " + why + "; issue a new key pair with issue-appliance --force instead");
    }
    const CertSpec spec{CertRole::appliance, ossl::subject_cn(old.get()), {}, -300, lifetime_s, KeyAlgorithm::ec_p256};
    ossl::Cert cert = build_cert(spec, X509_get0_pubkey(old.get()), ca_cert.get(), ca_key.get(), old.get());
    return ossl::cert_to_pem(cert.get());
}

std::vector<fs::path> pki_renew_appliance(const fs::path& dir, const std::string& name, int days) {
    if (auto why = check_pki_name(name); !why.empty()) throw PkiError(why);
    const std::int64_t lifetime_s = days_to_seconds(days);
    const PemPair ca = load_ca_files(dir);
    const fs::path path = appliance_cert_path(dir, name);
    std::string old;
    try {
        old = read_pem_file(path);
    } catch (const std::exception& e) {
        throw PkiError(std::string(e.what()) + " (renew-appliance renews what issue-appliance made)");
    }
    if (const ossl::Cert parsed = ossl::parse_cert(old); parsed && ossl::subject_cn(parsed.get()) != name) {
        throw PkiError(path.string() + " names CN=" + ossl::subject_cn(parsed.get()) + ", not '" + name + "'");
    }
    const std::string renewed = renew_appliance_cert(ca, old, lifetime_s, current_revocations(dir, ca));
    // The previous certificate stays valid until its notAfter with the same key: keep it, so that
    // `pki revoke --name` can revoke it too should the key leak.
    write_private_file(previous_appliance_cert_path(dir, name), old, true);
    write_private_file(path, renewed, true);
    return {path, previous_appliance_cert_path(dir, name)};
}

std::vector<fs::path> pki_export_farm(const fs::path& dir, const std::string& name, const fs::path& to, bool force) {
    if (auto why = check_pki_name(name); !why.empty()) throw PkiError(why);
    std::error_code ec;
    if (fs::equivalent(dir, to, ec))
        throw PkiError("export-farm: --to must be another folder than --dir (it holds ca.key)");
    std::vector<std::pair<fs::path, fs::path>> copies{{ca_cert_path(dir), ca_cert_path(to)},
                                                      {farm_cert_path(dir, name), farm_cert_path(to, name)},
                                                      {farm_key_path(dir, name), farm_key_path(to, name)}};
    if (fs::exists(crl_path(dir), ec)) copies.emplace_back(crl_path(dir), crl_path(to));
    std::vector<std::string> contents;
    for (const auto& [from, _] : copies) {
        try {
            contents.push_back(read_pem_file(from));
        } catch (const std::exception& e) {
            throw PkiError(std::string(e.what()) + " (pki issue-farm --dir " + dir.string() + " --name " + name + ")");
        }
    }
    std::vector<fs::path> targets;
    for (const auto& [_, target] : copies) targets.push_back(target);
    require_absent(targets, force);
    ensure_dir(to);
    for (std::size_t i = 0; i < copies.size(); ++i) write_private_file(copies[i].second, contents[i], force);
    return targets;
}

TlsMaterial load_farm_tls(const fs::path& dir, const std::string& name) {
    std::error_code ec;
    if (fs::exists(ca_key_path(dir), ec)) {
        throw LinkError(ca_key_path(dir).string() + ": the CA's private key is in the farm's TLS folder; keep it " +
                        "offline and serve from a folder made by `mogao-farm pki export-farm --dir " + dir.string() +
                        " --name " + name + " --to FOLDER` (docs/link.md)");
    }
    return load_tls_files(ca_cert_path(dir), farm_cert_path(dir, name), farm_key_path(dir, name));
}

TlsMaterial load_appliance_tls(const fs::path& dir, const std::string& name) {
    return load_tls_files(ca_cert_path(dir), appliance_cert_path(dir, name), appliance_key_path(dir, name));
}

void write_private_file(const fs::path& path, const std::string& content, bool force) {
    // With force, write a temporary and rename it over the old file: readers see the old or the
    // new file, never a half-written key.
    const fs::path target = force ? fs::path(path.string() + ".tmp") : path;
    if (force) ::unlink(target.c_str());  // a leftover of an interrupted run; ENOENT is fine
    const UniqueFd fd(::open(target.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600));
    if (!fd.valid()) {
        if (errno == EEXIST) throw PkiError("refusing to overwrite " + path.string() + " (use --force to replace it)");
        throw PkiError("cannot create " + target.string() + ": " + std::strerror(errno));
    }
    // On any failure remove what was created, so that a retry without --force is not refused.
    const auto failed = [&](const std::string& what) {
        const std::string reason = what + " " + target.string() + ": " + std::strerror(errno);
        ::unlink(target.c_str());
        throw PkiError(reason);
    };
    if (::fchmod(fd.get(), 0600) != 0) failed("cannot chmod 0600");
    std::size_t done = 0;
    while (done < content.size()) {
        const ssize_t n = ::write(fd.get(), content.data() + done, content.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) failed("cannot write");
        done += static_cast<std::size_t>(n);
    }
    if (::fsync(fd.get()) != 0) failed("cannot fsync");
    if (force && ::rename(target.c_str(), path.c_str()) != 0) failed("cannot rename to " + path.string() + ":");
}

}  // namespace mogao
