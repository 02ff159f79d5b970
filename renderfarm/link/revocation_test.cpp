// SPDX-License-Identifier: Apache-2.0
// The revocation list (revocation.h) and the CA key's place (pki.h): a CRL lists exactly what was
// revoked, only the farm CA's CRL counts, a changed file is re-read and a bad one never replaces
// the last good list; the farm serves from an exported folder that holds no ca.key.
#include "renderfarm/link/revocation.h"

#include <gtest/gtest.h>

#include <ctime>
#include <fstream>
#include <thread>

#include "common/link_types.h"
#include "renderfarm/link/link_test_support.h"
#include "renderfarm/link/pki.h"

namespace mogao {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;
using testing::TestPki;

// `mogao-farm pki ARGS...` in this process.
int run(std::vector<std::string> args) { return testing::run_pki(std::move(args)); }

void write_text(const fs::path& path, const std::string& text) {
    const fs::path tmp = path.string() + ".new";
    std::ofstream(tmp) << text;
    fs::rename(tmp, path);  // a new inode: the watcher sees the change whatever the mtime granularity
}

TEST(Revocation, CrlListsExactlyTheRevokedSerials) {
    const auto& pki = TestPki::get();
    const std::string museum1 = cert_serial_hex(pki.museum1.cert_pem);
    const std::string museum2 = cert_serial_hex(pki.museum2.cert_pem);
    ASSERT_FALSE(museum1.empty());
    ASSERT_NE(museum1, museum2);
    const RevocationList list = parse_crl(make_crl(pki.ca, {{museum1, 1'700'000'000}}, 86'400), pki.ca.cert_pem, "crl");
    ASSERT_EQ(list.revoked.size(), 1u);
    EXPECT_EQ(list.revoked[0].revoked_at_s, 1'700'000'000);
    EXPECT_TRUE(is_revoked(list, museum1));
    EXPECT_FALSE(is_revoked(list, museum2));
    EXPECT_GT(list.next_update_s, list.this_update_s);
    const RevocationList empty = parse_crl(make_crl(pki.ca, {}, 86'400), pki.ca.cert_pem, "crl");
    EXPECT_TRUE(empty.revoked.empty());
}

TEST(Revocation, OnlyTheFarmCasListCounts) {
    const auto& pki = TestPki::get();
    const std::string museum1 = cert_serial_hex(pki.museum1.cert_pem);
    const auto expect_refused = [&](const std::string& crl, const char* needle) {
        try {
            static_cast<void>(parse_crl(crl, pki.ca.cert_pem, "/etc/mogao/pki/crl.pem"));
            ADD_FAILURE() << "accepted; expected: " << needle;
        } catch (const LinkError& e) {
            EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("/etc/mogao/pki/crl.pem"), std::string::npos) << e.what();
        }
    };
    expect_refused(make_crl(pki.foreign_ca, {{museum1, 0}}, 86'400), "another CA");
    expect_refused("-----BEGIN X509 CRL-----\nAAAA\n-----END X509 CRL-----\n", "not a PEM");
    expect_refused(pki.museum1.cert_pem, "not a PEM");
    // One flipped byte of a good list's body: the signature no longer holds.
    std::string crl = make_crl(pki.ca, {{museum1, 0}}, 86'400);
    const auto body = crl.find('\n') + 40;
    crl[body] = crl[body] == 'A' ? 'B' : 'A';
    EXPECT_THROW(static_cast<void>(parse_crl(crl, pki.ca.cert_pem, "crl")), LinkError);
}

TEST(Revocation, WatcherReloadsAChangedFileAndKeepsTheLastGoodOne) {
    const auto& pki = TestPki::get();
    const TempDir tmp;
    const fs::path path = tmp.path() / "crl.pem";
    const std::string museum1 = cert_serial_hex(pki.museum1.cert_pem);
    const std::string museum2 = cert_serial_hex(pki.museum2.cert_pem);
    write_text(path, make_crl(pki.ca, {{museum1, 0}}, 86'400));
    RevocationWatcher watcher(path, pki.ca.cert_pem, std::chrono::milliseconds(0));
    EXPECT_TRUE(watcher.revoked(museum1));
    EXPECT_FALSE(watcher.revoked(museum2));
    const auto generation = watcher.generation();

    const std::int64_t before = std::time(nullptr);
    write_text(path, make_crl(pki.ca, {{museum1, 0}, {museum2, 0}}, 7 * 86'400));
    EXPECT_TRUE(watcher.revoked(museum2));
    EXPECT_GT(watcher.generation(), generation);
    // The list in force's nextUpdate (the farm's mogao_farm_crl_next_update_seconds).
    EXPECT_GE(watcher.next_update_s(), before + 7 * 86'400);
    EXPECT_LE(watcher.next_update_s(), std::time(nullptr) + 7 * 86'400);

    // A forged list (another CA) and a truncated one: the last good list stays in force.
    write_text(path, make_crl(pki.foreign_ca, {}, 86'400));
    EXPECT_TRUE(watcher.revoked(museum1));
    EXPECT_TRUE(watcher.revoked(museum2));
    write_text(path, "-----BEGIN X509 CRL-----\n");
    EXPECT_TRUE(watcher.revoked(museum2));
    fs::remove(path);
    EXPECT_TRUE(watcher.revoked(museum2));
    EXPECT_GE(watcher.next_update_s(), before + 7 * 86'400) << "the last good list's";

    EXPECT_THROW(RevocationWatcher(tmp.path() / "missing.pem", pki.ca.cert_pem), LinkError);
}

TEST(Revocation, PkiRevokeAddsTheCertificateOnce) {
    const TempDir tmp;
    const fs::path dir = tmp.path() / "ca";
    ASSERT_EQ(run({"init-ca", "--dir", dir.string()}), 0);
    ASSERT_EQ(run({"issue-appliance", "--dir", dir.string(), "--name", "museum-1"}), 0);
    ASSERT_EQ(run({"issue-appliance", "--dir", dir.string(), "--name", "museum-2"}), 0);
    ASSERT_EQ(run({"crl", "--dir", dir.string()}), 0);  // an empty list to start with
    const std::string ca = read_pem_file(ca_cert_path(dir));
    EXPECT_TRUE(parse_crl(read_pem_file(crl_path(dir)), ca, "crl").revoked.empty());

    ASSERT_EQ(run({"revoke", "--dir", dir.string(), "--name", "museum-1"}), 0);
    ASSERT_EQ(run({"revoke", "--dir", dir.string(), "--cert", appliance_cert_path(dir, "museum-1").string()}), 0);
    const RevocationList list = parse_crl(read_pem_file(crl_path(dir)), ca, "crl");
    ASSERT_EQ(list.revoked.size(), 1u);
    EXPECT_TRUE(is_revoked(list, cert_serial_hex(read_pem_file(appliance_cert_path(dir, "museum-1")))));
    EXPECT_FALSE(is_revoked(list, cert_serial_hex(read_pem_file(appliance_cert_path(dir, "museum-2")))));
    // Re-issued with a fresh nextUpdate, same entries.
    ASSERT_EQ(run({"crl", "--dir", dir.string(), "--days", "7"}), 0);
    EXPECT_EQ(parse_crl(read_pem_file(crl_path(dir)), ca, "crl").revoked.size(), 1u);

    EXPECT_EQ(run({"revoke", "--dir", dir.string()}), 1);                      // neither --name nor --cert
    EXPECT_EQ(run({"revoke", "--dir", dir.string(), "--name", "nobody"}), 1);  // no such certificate
    EXPECT_EQ(run({"revoke", "--dir", (tmp.path() / "none").string(), "--name", "museum-1"}), 1);  // no CA
}

TEST(CaKey, FarmServesFromAnExportedFolderWithoutTheCaKey) {
    const TempDir tmp;
    const fs::path dir = tmp.path() / "ca", served = tmp.path() / "farm-tls";
    ASSERT_EQ(run({"init-ca", "--dir", dir.string()}), 0);
    ASSERT_EQ(run({"issue-farm", "--dir", dir.string(), "--name", "farm", "--san", "::1"}), 0);
    try {
        static_cast<void>(load_farm_tls(dir, "farm"));
        ADD_FAILURE() << "the farm loaded its TLS material from a folder holding ca.key";
    } catch (const LinkError& e) {
        EXPECT_NE(std::string(e.what()).find("ca.key"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("export-farm"), std::string::npos) << e.what();
    }
    ASSERT_EQ(run({"crl", "--dir", dir.string()}), 0);
    ASSERT_EQ(run({"export-farm", "--dir", dir.string(), "--name", "farm", "--to", served.string()}), 0);
    EXPECT_FALSE(fs::exists(ca_key_path(served)));
    EXPECT_TRUE(fs::exists(crl_path(served)));
    const TlsMaterial tls = load_farm_tls(served, "farm");
    EXPECT_EQ(tls.ca_pem, read_pem_file(ca_cert_path(dir)));
    EXPECT_EQ(check_tls_material(tls, "farm").error, "");
    // Not into the CA folder itself, not over existing files without --force.
    EXPECT_EQ(run({"export-farm", "--dir", dir.string(), "--name", "farm", "--to", dir.string()}), 1);
    EXPECT_EQ(run({"export-farm", "--dir", dir.string(), "--name", "farm", "--to", served.string()}), 1);
    EXPECT_EQ(run({"export-farm", "--dir", dir.string(), "--name", "farm", "--to", served.string(), "--force"}), 0);
    EXPECT_EQ(run({"export-farm", "--dir", dir.string(), "--name", "other", "--to", served.string()}), 1);
}

}  // namespace
}  // namespace mogao
