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

// The flags of every pki command, and which command was given.
struct PkiFlags {
    std::string dir, name, san, key = "ec", cert, to;
    int days = 0;
    bool force = false;
    CLI::App *init = nullptr, *farm = nullptr, *appliance = nullptr, *renew = nullptr, *revoke = nullptr,
             *crl = nullptr, *export_farm = nullptr;
};

void add_pki_commands(CLI::App& app, PkiFlags& f) {
    const auto common = [&](CLI::App* sub) {
        sub->add_option("--dir", f.dir, "PKI folder (created 0700 if missing)")->required();
        sub->add_flag("--force", f.force, "Replace existing files (atomically)");
    };
    f.init = app.add_subcommand("init-ca", "Create the farm CA: ca.pem + ca.key");
    common(f.init);
    f.init->add_option("--name", f.name, "CA common name")->default_val("mogao farm CA");
    add_days(*f.init, f.days, 3650);
    f.init->add_option("--key", f.key, "Key type: ec (P-256) | rsa (3072 bits)")->check(CLI::IsMember({"ec", "rsa"}));
    f.farm = app.add_subcommand("issue-farm", "Issue the farm's server certificate: farm-NAME.pem + .key");
    common(f.farm);
    f.farm->add_option("--name", f.name, "Farm host name (also a DNS SAN)")->required();
    f.farm->add_option("--san", f.san, "Comma-separated IPv6 addresses (IP SANs) or DNS names, e.g. ::1,2001:db8::5")
        ->required();
    add_days(*f.farm, f.days, 825);
    f.appliance =
        app.add_subcommand("issue-appliance", "Issue an appliance client certificate: appliance-NAME.pem + .key");
    common(f.appliance);
    f.appliance->add_option("--name", f.name, "Appliance name, e.g. museum-1")->required();
    add_days(*f.appliance, f.days, 365);
    f.renew = app.add_subcommand(
        "renew-appliance",
        "Re-sign appliance-NAME.pem's public key with a new validity (no new key pair; refused for a certificate "
        "this CA did not issue, a revoked one or a key weaker than EC P-256)");
    f.renew->add_option("--dir", f.dir, "PKI folder (with ca.key)")->required();
    f.renew->add_option("--name", f.name, "Appliance name: renews appliance-NAME.pem in --dir")->required();
    add_days(*f.renew, f.days, 365);
    f.revoke = app.add_subcommand("revoke", "Revoke an appliance certificate: add it to crl.pem (re-signed)");
    f.revoke->add_option("--dir", f.dir, "PKI folder (with ca.key)")->required();
    auto* by_name = f.revoke->add_option("--name", f.name, "Appliance name: revokes appliance-NAME.pem in --dir");
    f.revoke->add_option("--cert", f.cert, "Or the certificate file to revoke")->excludes(by_name);
    add_days(*f.revoke, f.days, 30);
    f.crl = app.add_subcommand("crl", "Re-issue crl.pem with the same entries and a fresh nextUpdate");
    f.crl->add_option("--dir", f.dir, "PKI folder (with ca.key)")->required();
    add_days(*f.crl, f.days, 30);
    f.export_farm = app.add_subcommand(
        "export-farm", "Copy what the farm serves with (ca.pem, crl.pem, farm-NAME.pem/.key; never ca.key) to --to");
    common(f.export_farm);
    f.export_farm->add_option("--name", f.name, "Farm certificate name")->required();
    f.export_farm->add_option("--to", f.to, "The farm's TLS folder (mogao-farm serve --tls-dir)")->required();
}

// Runs the command given; returns the files written. Throws PkiError (or std::exception) naming the file.
std::vector<std::filesystem::path> run_pki(const PkiFlags& f) {
    const std::string& dir = f.dir;
    const std::string& name = f.name;
    if (f.init->parsed()) {
        return pki_init_ca(dir, name, f.days, f.key == "rsa" ? KeyAlgorithm::rsa_3072 : KeyAlgorithm::ec_p256, f.force);
    }
    if (f.farm->parsed()) return pki_issue_farm(dir, name, split_sans(f.san), f.days, f.force);
    if (f.appliance->parsed()) return pki_issue_appliance(dir, name, f.days, f.force);
    if (f.renew->parsed()) return pki_renew_appliance(dir, name, f.days);
    if (f.revoke->parsed()) {
        if (name.empty() && f.cert.empty()) throw PkiError("revoke: give --name or --cert");
        auto written =
            pki_revoke(dir, f.cert.empty() ? appliance_cert_path(dir, name) : std::filesystem::path(f.cert), f.days);
        // By name: the certificate a renewal replaced shares the key, so it goes too.
        if (f.cert.empty() && std::filesystem::exists(previous_appliance_cert_path(dir, name)))
            written = pki_revoke(dir, previous_appliance_cert_path(dir, name), f.days);
        return written;
    }
    if (f.crl->parsed()) return pki_refresh_crl(dir, f.days);
    return pki_export_farm(dir, name, f.to, f.force);
}

}  // namespace

int run_pki_command(int argc, char** argv) {
    CLI::App app{
        "mogao link PKI: the farm CA, the farm's server certificate, one client certificate per "
        "appliance and the revocation list (files mode 0600; docs/link.md)",
        "pki"};
    app.require_subcommand(1);
    PkiFlags flags;
    add_pki_commands(app, flags);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);  // prints help or the error
        return code == 0 ? 0 : 2;
    }
    try {
        for (const auto& path : run_pki(flags)) std::cout << path.string() << '\n';
        return 0;
    } catch (const std::exception& e) {
        link_log().error("pki: {}", e.what());
        return 1;
    }
}

}  // namespace mogao
