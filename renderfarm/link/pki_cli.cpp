// SPDX-License-Identifier: Apache-2.0
// `mogao-farm pki ...`: the command line of the farm's appliance CA (pki.h).
#include <CLI/CLI.hpp>

#include <iostream>
#include <sstream>

#include "renderfarm/link/link_log.h"
#include "renderfarm/link/pki.h"

namespace mogao {
namespace {

std::vector<std::string> split_sans(const std::string& text) {
    std::vector<std::string> out;
    std::stringstream in(text);
    for (std::string item; std::getline(in, item, ',');) {
        if (!item.empty()) out.push_back(item);
    }
    return out;
}

// --days: one name, one meaning (docs/cli.md): the validity of what the command signs, from now.
void add_days(CLI::App& sub, int& days, int default_days) {
    sub.add_option("--days", days,
                   "Validity from now in days of what it signs (a certificate, or crl.pem's nextUpdate)")
        ->default_val(default_days)
        ->check(CLI::Range(1, 36500));
}

}  // namespace

int run_pki_command(int argc, char** argv) {
    CLI::App app{
        "mogao link PKI: the farm CA, the farm's server certificate, one client certificate per "
        "appliance and the revocation list (files mode 0600; docs/link.md)",
        "pki"};
    app.require_subcommand(1);
    std::string dir, name, san, key = "ec";
    int days = 0;
    bool force = false;
    const auto common = [&](CLI::App* sub) {
        sub->add_option("--dir", dir, "PKI folder (created 0700 if missing)")->required();
        sub->add_flag("--force", force, "Replace existing files (atomically)");
    };
    CLI::App* init = app.add_subcommand("init-ca", "Create the farm CA: ca.pem + ca.key");
    common(init);
    init->add_option("--name", name, "CA common name")->default_val("mogao farm CA");
    add_days(*init, days, 3650);
    init->add_option("--key", key, "Key type: ec (P-256) | rsa (3072 bits)")->check(CLI::IsMember({"ec", "rsa"}));
    CLI::App* farm = app.add_subcommand("issue-farm", "Issue the farm's server certificate: farm-NAME.pem + .key");
    common(farm);
    farm->add_option("--name", name, "Farm host name (also a DNS SAN)")->required();
    farm->add_option("--san", san, "Comma-separated IPv6 addresses (IP SANs) or DNS names, e.g. ::1,2001:db8::5")
        ->required();
    add_days(*farm, days, 825);
    CLI::App* appliance =
        app.add_subcommand("issue-appliance", "Issue an appliance client certificate: appliance-NAME.pem + .key");
    common(appliance);
    appliance->add_option("--name", name, "Appliance name, e.g. museum-1")->required();
    add_days(*appliance, days, 365);
    CLI::App* renew = app.add_subcommand(
        "renew-appliance",
        "Re-sign appliance-NAME.pem's public key with a new validity (no new key pair; refused for a certificate "
        "this CA did not issue, a revoked one or a key weaker than EC P-256)");
    renew->add_option("--dir", dir, "PKI folder (with ca.key)")->required();
    renew->add_option("--name", name, "Appliance name: renews appliance-NAME.pem in --dir")->required();
    add_days(*renew, days, 365);
    std::string cert, to;
    CLI::App* revoke = app.add_subcommand("revoke", "Revoke an appliance certificate: add it to crl.pem (re-signed)");
    revoke->add_option("--dir", dir, "PKI folder (with ca.key)")->required();
    auto* by_name = revoke->add_option("--name", name, "Appliance name: revokes appliance-NAME.pem in --dir");
    revoke->add_option("--cert", cert, "Or the certificate file to revoke")->excludes(by_name);
    add_days(*revoke, days, 30);
    CLI::App* crl = app.add_subcommand("crl", "Re-issue crl.pem with the same entries and a fresh nextUpdate");
    crl->add_option("--dir", dir, "PKI folder (with ca.key)")->required();
    add_days(*crl, days, 30);
    CLI::App* export_farm = app.add_subcommand(
        "export-farm", "Copy what the farm serves with (ca.pem, crl.pem, farm-NAME.pem/.key; never ca.key) to --to");
    common(export_farm);
    export_farm->add_option("--name", name, "Farm certificate name")->required();
    export_farm->add_option("--to", to, "The farm's TLS folder (mogao-farm serve --tls-dir)")->required();
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);  // prints help or the error
        return code == 0 ? 0 : 2;
    }
    try {
        std::vector<std::filesystem::path> written;
        if (init->parsed()) {
            written =
                pki_init_ca(dir, name, days, key == "rsa" ? KeyAlgorithm::rsa_3072 : KeyAlgorithm::ec_p256, force);
        } else if (farm->parsed()) {
            written = pki_issue_farm(dir, name, split_sans(san), days, force);
        } else if (appliance->parsed()) {
            written = pki_issue_appliance(dir, name, days, force);
        } else if (renew->parsed()) {
            written = pki_renew_appliance(dir, name, days);
        } else if (revoke->parsed()) {
            if (name.empty() && cert.empty()) throw PkiError("revoke: give --name or --cert");
            written =
                pki_revoke(dir, cert.empty() ? appliance_cert_path(dir, name) : std::filesystem::path(cert), days);
            // By name: the certificate a renewal replaced shares the key, so it goes too.
            if (cert.empty() && std::filesystem::exists(previous_appliance_cert_path(dir, name)))
                written = pki_revoke(dir, previous_appliance_cert_path(dir, name), days);
        } else if (crl->parsed()) {
            written = pki_refresh_crl(dir, days);
        } else {
            written = pki_export_farm(dir, name, to, force);
        }
        for (const auto& path : written) std::cout << path.string() << '\n';
        return 0;
    } catch (const std::exception& e) {
        link_log().error("pki: {}", e.what());
        return 1;
    }
}

}  // namespace mogao
