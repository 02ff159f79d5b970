// SPDX-License-Identifier: Apache-2.0
// When the certificates each side of the link holds expire, so that a lapse is seen weeks before
// the farm refuses a gallery: the farm reports them as a Prometheus gauge
// (mogao_farm_certificate_not_after_seconds, renderfarm/farm/farm_metrics.h), the kiosk in its
// status file and on its on-wall status panel (kiosk/stats/kiosk_status.h, kiosk/display/on_wall_status.h), and
// both log a warning at start for any that expires within kCertificateWarningSeconds.
//
// Held: every certificate of the CA bundle (role "ca") and the side's own certificate (role
// "farm" or "appliance"). Times are seconds since the Unix epoch (UTC), X.509's own resolution.
// Errors: certificate_not_after_s throws LinkError; the others leave out what does not parse
// (check_tls_material, tls_material.h, names it).
#pragma once

#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "renderfarm/link/tls_material.h"

namespace mogao {

struct CertificateExpiry {
    std::string role;              // "ca", "farm" or "appliance"
    std::string name;              // the subject's common name
    std::int64_t not_after_s = 0;  // notAfter, seconds since the Unix epoch
    bool operator==(const CertificateExpiry&) const = default;
};

// Warn this long before a certificate expires (the appliance default lifetime is 365 days).
inline constexpr std::int64_t kCertificateWarningSeconds = 30 * 86'400;

// notAfter of the first certificate in `cert_pem`. Throws LinkError when the text holds none.
[[nodiscard]] std::int64_t certificate_not_after_s(const std::string& cert_pem);

// The certificates of `material`: each of its CA certificates (role "ca"), then its own
// (`own_role`).
[[nodiscard]] std::vector<CertificateExpiry> certificate_expiries(const TlsMaterial& material,
                                                                  const std::string& own_role);

// Whole days from `now_s` until `not_after_s`, rounded down (negative once expired).
[[nodiscard]] std::int64_t days_left(std::int64_t not_after_s, std::int64_t now_s);

// True when the certificate expires within `within_s` of `now_s` (or has expired); never for
// within_s <= 0.
[[nodiscard]] bool expires_soon(const CertificateExpiry& cert, std::int64_t now_s, std::int64_t within_s);

// One line for each certificate that expires_soon, e.g. "the farm certificate CN=farm-1 expires
// in 12 days (2026-12-08T10:00:00Z): renew it (docs/link.md, \"Renewing certificates\")".
[[nodiscard]] std::vector<std::string> expiry_warnings(const std::vector<CertificateExpiry>& certs, std::int64_t now_s,
                                                       std::int64_t within_s);

// "2026-12-08T10:00:00Z" for seconds since the Unix epoch.
[[nodiscard]] std::string utc_seconds_text(std::int64_t unix_s);

// The certificates a running side holds while its TLS files may be rotated: certificate_expiries of
// the material it started with, then of `files` whenever they changed and still check
// (check_tls_material without error: the pair gRPC and the link client would take), looked at
// most once per `refresh`. Thread-safe.
class HeldCertificates {
public:
    HeldCertificates(const TlsMaterial& material, TlsFilePaths files, std::string own_role,
                     std::chrono::seconds refresh);
    [[nodiscard]] std::vector<CertificateExpiry> current();

private:
    TlsFilePaths files_;
    std::string own_role_;
    std::chrono::seconds refresh_;
    std::mutex mutex_;
    std::vector<CertificateExpiry> held_;
    TlsMaterial last_;
    std::chrono::steady_clock::time_point next_look_;
};

}  // namespace mogao
