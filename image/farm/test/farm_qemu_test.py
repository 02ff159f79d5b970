#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Installs the mogao-farm package on two stock Debian 12 render hosts in QEMU and checks
mogao-farm.service end to end.

    farm_qemu_test.py --image mogao-farm.img --deb mogao-farm_VERSION_amd64.deb --repo SRC --farm BIN
                      --kiosk BIN [--image-tool BIN] [--work DIR] [--results FILE] [--timeout S]

Two provisioned copies of the render-host image (image/farm/build: Debian 12 with the package's
dependencies, no mogao program; image/farm/provision: names, network, host keys, the package
file) boot under TCG with OVMF on a bridge in a private network namespace (taps; the host side is
fd00:6d6f::1 and 10.77.0.1). On each, the test's unit does what docs/packaging.md tells a
technician: `apt install ./mogao-farm_*.deb` (offline: the dependencies are in the image), then
the site's files (farm.env, farm-hosts, the TLS folder, the farm user's ssh files), the packet
filter reloaded, and on the admin `systemctl enable --now mogao-farm` once farm-render2 answers:
  farm-admin    fd00:6d6f::10, 10.77.0.10: mogao-farm.service, farm-hosts = farm-admin (2 slots)
                + farm-render2 (1 slot), MOGAO_RANKS=3, the farm's PKI (SAN fd00:6d6f::10)
  farm-render2  fd00:6d6f::11, 10.77.0.11: sshd for the mogao-farm user (key only)
Each copy also gets a test-only unit that runs image/farm/test/selftest.sh and reports on the
serial console; the shipped image is not changed. The host is the appliance: mogao-kiosk runs
headless in the namespace against [fd00:6d6f::10]:7443.

Assertions (each printed as PASS/FAIL; any failure fails the test):
  * on both hosts the package installs with apt: the mogao-farm user (971), the unit enabled and
    not started before its TLS files exist;
  * mogao-farm.service on farm-admin reaches active (Type=notify READY) as user mogao-farm;
  * ranks run on both hosts (rank 2 on farm-render2, started over ssh by mpirun) and the admin
    serves with 2 render ranks (--layout both, the default; admin-only runs every rank on
    farm-admin, for diagnosis);
  * the host's kiosk connects over IPv6 + mutual TLS and presents farm frames (not black);
  * the farm stays up without restarts for longer than WatchdogSec (WATCHDOG=1 reaches systemd);
  * a SIGSTOPped admin rank is killed by WatchdogSec and the farm restarted (NRestarts 0 -> 1),
    its rank on farm-render2 replaced;
  * hardening at run time: seccomp and no_new_privs on the ranks, listening sockets only the farm
    port, sshd and Open MPI's own port ranges; systemd-analyze security (online) recorded;
  * the packet filter (mogao-farm-firewall.service): from the host's addresses outside the farm
    network (fd00:6d6f:9::1, 10.77.9.1) a rank's port and mpirun's are dropped, sshd and the link
    answer; from the farm network the rank's port answers;
  * no failed units on either host.
Exit 77 (skip) with a message when root, QEMU, OVMF, mtools, tun, ip netns or the image are missing.
"""
import argparse
import json
import os
import signal
import re
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import farmvm  # noqa: E402  (QEMU, serial and network helpers of this test)
import host_loss  # noqa: E402  (--host-loss: a render host lost and back while serving)

SKIP = 77
PORT = 7443
HOSTS = {  # name -> (last part of both addresses, MAC, memory MiB)
    "farm-admin": ("10", "52:54:00:6d:6f:10", 2048),
    "farm-render2": ("11", "52:54:00:6d:6f:11", 1536),
}
V6 = "fd00:6d6f::"
V4 = "10.77.0."
# The host's addresses outside the farm network (a museum's, an attacker's): routed to the hosts
# through the host's farm address (their gateway). Only sshd and the link may answer them.
OUTSIDE_V6 = "fd00:6d6f:9::1"
OUTSIDE_V4 = "10.77.9.1"
FARM_NETWORK = f"{V4}0/24\n{V6}/64\n"
RANKS = 3
HEALTH_TIMEOUT_S = 30      # mogao-farm-launch's ssh health check of farm-render2 (TCG: slow logins)
SCENE = "/usr/share/mogao/scenes/test-room.json"
KIOSK_FRAMES = 4           # farm frames the host's kiosk must present before it stops
KIOSK_TIMEOUT_S = 420
log = farmvm.log


def skip(msg):
    print(f"SKIP: {msg}", flush=True)
    sys.exit(SKIP)


def run(cmd, **kw):
    return subprocess.run(cmd, check=True, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, **kw)


def write(path, text, mode=0o644):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(text)
    os.chmod(path, mode)


# Inside each host: the package and the site's files that the test's unit installs after it
# (selftest.sh), as a technician would after `apt install` (docs/packaging.md).
STAGE = "var/lib/mogao-test"


def host_dirs(work, farm, deb, overlay, layout):
    """PKI, ssh keys and the two hosts' provisioning folders (image/farm/provision's HOST_DIR): the
    host's own files in place, the package and the farm's configuration under STAGE."""
    pki = os.path.join(work, "pki")
    keys = os.path.join(work, "ssh")
    for d in (pki, keys):
        shutil.rmtree(d, ignore_errors=True)
        os.makedirs(d)
    run([farm, "pki", "init-ca", "--dir", pki])
    run([farm, "pki", "issue-farm", "--dir", pki, "--name", "farm", "--san", f"{V6}10"])
    run([farm, "pki", "issue-appliance", "--dir", pki, "--name", "museum-1"])
    run(["ssh-keygen", "-q", "-t", "ed25519", "-N", "", "-C", "mogao-farm@farm-admin", "-f",
         os.path.join(keys, "user")])
    for name in HOSTS:
        run(["ssh-keygen", "-q", "-t", "ed25519", "-N", "", "-C", f"root@{name}", "-f", os.path.join(keys, name)])
    read = lambda p: open(p).read().strip()
    hosts_file = "127.0.0.1\tlocalhost\n::1\t\tlocalhost ip6-localhost ip6-loopback\n" + "".join(
        f"{V4}{n}\t{name}\n" for name, (n, _, _) in HOSTS.items())
    dirs = {}
    for name, (n, mac, _) in HOSTS.items():
        d = os.path.join(work, "hosts", name)
        shutil.rmtree(d, ignore_errors=True)
        if overlay:
            # This tree's image files, without rebuilding the image (host files follow).
            shutil.copytree(os.path.join(overlay, "image", "farm", "rootfs"), d, symlinks=True)
        write(f"{d}/etc/hostname", name + "\n")
        write(f"{d}/etc/hosts", hosts_file)
        write(f"{d}/etc/systemd/network/10-farm.network",
              f"# {name}: the farm's network (written by farm_qemu_test.py)\n[Match]\nMACAddress={mac}\n\n"
              f"[Network]\nAddress={V6}{n}/64\nAddress={V4}{n}/24\nGateway={V6}1\nGateway={V4}1\n"
              "IPv6AcceptRA=no\nLinkLocalAddressing=ipv6\nLLMNR=no\nMulticastDNS=no\n")
        # The packet filter's farm network (mogao-farm-firewall.service): Open MPI's ports from it only.
        write(f"{d}/etc/mogao/farm-network", f"# the farm's network (written by farm_qemu_test.py)\n{FARM_NETWORK}")
        os.makedirs(f"{d}/{STAGE}/site", exist_ok=True)
        shutil.copy(deb, f"{d}/{STAGE}/")
        os.makedirs(f"{d}/etc/ssh", exist_ok=True)
        shutil.copy(os.path.join(keys, name), f"{d}/etc/ssh/ssh_host_ed25519_key")
        shutil.copy(os.path.join(keys, name + ".pub"), f"{d}/etc/ssh/ssh_host_ed25519_key.pub")
        # Test only: the self-test unit and script, and the journal on the serial console.
        write(f"{d}/usr/local/lib/mogao-farm-selftest.sh", open(os.path.join(HERE, "selftest.sh")).read(), 0o755)
        role = "admin" if name == "farm-admin" else "render"
        write(f"{d}/etc/systemd/system/mogao-farm-selftest.service",
              "[Unit]\nDescription=mogao farm QEMU self-test (test copy only)\nAfter=systemd-networkd.service\n\n"
              f"[Service]\nType=exec\nExecStart=/bin/sh /usr/local/lib/mogao-farm-selftest.sh {role}\n\n"
              "[Install]\nWantedBy=multi-user.target\n")
        os.makedirs(f"{d}/etc/systemd/system/multi-user.target.wants", exist_ok=True)
        os.symlink("/etc/systemd/system/mogao-farm-selftest.service",
                   f"{d}/etc/systemd/system/multi-user.target.wants/mogao-farm-selftest.service")
        write(f"{d}/etc/systemd/journald.conf.d/90-test-console.conf",
              "[Journal]\nForwardToConsole=yes\nTTYPath=/dev/ttyS0\nMaxLevelConsole=info\n")
        dirs[name] = d
    admin, render = (f"{dirs[n]}/{STAGE}/site" for n in ("farm-admin", "farm-render2"))
    if layout == "admin-only":
        # Diagnosis: every rank on farm-admin (the unit, READY, the watchdog, the link without
        # Open MPI between the hosts).
        write(f"{admin}/etc/mogao/farm-hosts", f"farm-admin slots={RANKS}\n")
        write(f"{render}/etc/mogao/no-ranks-here", "test copy: every rank runs on farm-admin\n")
    else:
        write(f"{admin}/etc/mogao/farm-hosts", "farm-admin slots=2\nfarm-render2 slots=1\n")
    write(f"{admin}/etc/mogao/farm.env",
          f"MOGAO_RANKS={RANKS}\nMOGAO_SCENE={SCENE}\nMOGAO_LISTEN=[::]:{PORT}\nMOGAO_FARM_NAME=farm\n"
          "# Open MPI between the hosts: the farm's IPv4 network only.\n"
          f"OMPI_MCA_btl_tcp_if_include={V4}0/24\nOMPI_MCA_oob_tcp_if_include={V4}0/24\n"
          "# Under TCG an ssh login takes seconds: the launcher's 2 s health check would leave\n"
          "# farm-render2 out (mogao-farm-launch, 'no answer within 2 s').\n"
          f"MOGAO_HEALTH_TIMEOUT_S={HEALTH_TIMEOUT_S}\n"
          + ("OMPI_MCA_btl_base_verbose=30\n" if os.environ.get("MOGAO_FARM_TEST_MPI_VERBOSE") else "")
          # Diagnosis: more farm.env lines, space-separated NAME=VALUE (e.g. PMIX_MCA_gds=hash).
          + "".join(f"{kv}\n" for kv in os.environ.get("MOGAO_FARM_TEST_FARM_ENV", "").split()))
    for f in ("ca.pem", "farm-farm.pem", "farm-farm.key"):
        os.makedirs(f"{admin}/etc/mogao/pki", exist_ok=True)
        shutil.copy(os.path.join(pki, f), f"{admin}/etc/mogao/pki/{f}")
    ssh = f"{admin}/var/lib/mogao-farm/.ssh"
    os.makedirs(ssh)
    shutil.copy(os.path.join(keys, "user"), f"{ssh}/id_ed25519")
    shutil.copy(os.path.join(keys, "user.pub"), f"{ssh}/id_ed25519.pub")
    write(f"{ssh}/known_hosts", "".join(
        f"{name},{V4}{n} {read(os.path.join(keys, name + '.pub')).rsplit(' ', 1)[0]}\n"
        for name, (n, _, _) in HOSTS.items()))
    # restrict: no forwarding, no pty; the farm user only runs commands (orted) there.
    write(f"{render}/var/lib/mogao-farm/.ssh/authorized_keys",
          f"restrict,from=\"{V4}10\" {read(os.path.join(keys, 'user.pub'))}\n")
    return pki, dirs


def expect_ok(serial, marker, timeout, alive, fails, what):
    """Waits up to TIMEOUT s for selftest.sh's 'ok MARKER' or 'FAIL MARKER' line and checks that it
    is ok (WHAT: the check, in words). Returns the line when ok, else None."""
    _, text = serial.wait(rf"(ok|FAIL) {marker}", timeout, alive)
    ok = fails.check(text is not None and text.startswith("ok"), f"{what}: {text}")
    return text if ok else None


def kiosk_config(kiosk, work, pki):
    """kiosk/config/kiosk.example.toml with this test's overrides (mogao-kiosk --print-config; section.key=TOML value,
    empty: commented out): headless, one 320x180 output, the walk."""
    out = os.path.join(work, "kiosk")
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(os.path.join(out, "png"))
    os.makedirs(os.path.join(out, "content"))
    path = os.path.join(out, "kiosk.toml")
    overrides = [f'farm.endpoint="[{V6}10]:{PORT}"', f'farm.ca="{pki}/ca.pem"',
                 f'farm.cert="{pki}/appliance-museum-1.pem"',
                 f'farm.key="{pki}/appliance-museum-1.key"', "display.rate_hz=2", 'outputs.backend="headless"',
                 'outputs.sizes=["320x180"]', f'outputs.png_dir="{out}/png"', "outputs.png_every=1",
                 "outputs.composite=false", 'calibration.source="ideal"', "calibration.projectors=1",
                 "calibration.overlap=0.0", 'calibration.output="320x180"', 'quality.content="320x180"',
                 'navigation.path="walk"', "navigation.path_frames=240", "navigation.start=[0.0, 0.0, 4.0]",
                 "stats.file=", "stats.log_period_s=5"]
    printed = subprocess.run([kiosk, "--print-config", *overrides], check=True, stdout=subprocess.PIPE, text=True)
    write(path, "# written by image/farm/test/farm_qemu_test.py: the host plays the appliance\n" + printed.stdout)
    return out, path


def check_packet_filter(net, serials, fails, results):
    """Open MPI's ports answer the farm network only (mogao-farm-firewall.service): a rank's port and
    mpirun's from outside are dropped, sshd and the link answer everyone, the same rank port answers
    from inside the farm network (so a drop is the filter, not a missing listener)."""
    admin, render = f"{V4}10", f"{V4}11"
    # Marks "listen tcp ADDR:PORT PROCESS" (selftest.sh listeners).
    listens = [m.split() for _, m in serials["farm-admin"].marks if m.startswith("listen tcp ")]
    ports = [(w[2].rsplit(":", 1)[1], w[-1]) for w in listens]
    mpirun_ports = [int(p) for p, proc in ports if proc == "mpirun" and p.isdigit()]
    probes = [  # (what, source, destination, port, expected)
        ("a rank's port from the farm network", f"{V4}1", admin, 46000, "open"),
        ("a rank's port from outside (IPv4)", OUTSIDE_V4, admin, 46000, "timeout"),
        ("a rank's port from outside (IPv6)", OUTSIDE_V6, f"{V6}10", 46000, "timeout"),
        ("the link from outside", OUTSIDE_V6, f"{V6}10", PORT, "open"),
        ("sshd on farm-render2 from outside", OUTSIDE_V4, render, 22, "open"),
        ("a rank's port on farm-render2 from outside", OUTSIDE_V4, render, 46000, "timeout"),
    ]
    probes += [("mpirun's port from outside", OUTSIDE_V4, admin, p, "timeout") for p in mpirun_ports[:1]]
    fails.check(bool(mpirun_ports), f"farm-admin: mpirun listens (its port is probed from outside): {mpirun_ports}")
    results["packet_filter"] = {}
    for what, src, dst, port, expected in probes:
        got = net.tcp_probe(src, dst, port)
        results["packet_filter"][f"{src} -> {dst}:{port}"] = got
        fails.check(got == expected, f"packet filter: {what} ({src} -> {dst}:{port}) is {expected}: {got}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--image", required=True, help="the render-host image (image/farm/build)")
    ap.add_argument("--deb", required=True, help="the mogao-farm package the hosts install")
    ap.add_argument("--repo", required=True)
    ap.add_argument("--farm", required=True, help="mogao-farm (host): the PKI")
    ap.add_argument("--kiosk", required=True, help="mogao-kiosk (host): the appliance, headless")
    ap.add_argument("--image-tool", default="", help="mogao_kiosk_image_tool: PNG statistics")
    ap.add_argument("--work", default="")
    ap.add_argument("--layout", choices=["both", "admin-only"],
                    default=os.environ.get("MOGAO_FARM_TEST_LAYOUT", "both"),
                    help="both: ranks on farm-admin and farm-render2 (the test); admin-only: every rank on "
                         "farm-admin (diagnosis: the unit and the link without MPI between the hosts)")
    ap.add_argument("--overlay", action="store_true",
                    help="write this tree's image/farm/rootfs/ into the copies (try changes to it without "
                         "rebuilding the image)")
    ap.add_argument("--host-loss", action="store_true", default=os.environ.get("MOGAO_FARM_TEST_HOST_LOSS") == "1",
                    help="also lose farm-render2 while the appliance is served (its link cut, then its VM "
                         "killed) and measure the new frame and its return (host_loss.py; ~8 more minutes)")
    ap.add_argument("--results", default="")
    ap.add_argument("--build-seconds", type=float, default=None, help="image build time, for the results")
    ap.add_argument("--timeout", type=float, default=float(os.environ.get("MOGAO_FARM_BOOT_TIMEOUT", "900")))
    a = ap.parse_args()
    # SIGTERM (ctest's timeout, a user) ends like an error: the finally blocks stop QEMU and delete
    # the network namespace.
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(1))

    if os.geteuid() != 0:
        skip("needs root (network namespace, taps, provisioning files owned by mogao-farm)")
    missing = farmvm.missing_tools()
    if missing:
        skip(missing)
    if not os.path.isfile(a.image):
        skip(f"no image at {a.image} (image/farm/build, or the farm_image_build test, makes it)")
    if not os.path.isfile(a.deb):
        skip(f"no package at {a.deb} (bash .ci/package, or the farm_packages_build test, makes it)")
    for b in (a.farm, a.kiosk):
        if not os.access(b, os.X_OK):
            skip(f"{b} not built")

    work = a.work or tempfile.mkdtemp(prefix="mogao-farmvm-")
    os.makedirs(work, exist_ok=True)
    log(f"work folder {work}")
    fails = farmvm.Failures()
    commit = subprocess.run(["git", "-C", a.repo, "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    results = {"accel": "tcg", "image_bytes": os.path.getsize(a.image),
               "image_allocated_bytes": os.stat(a.image).st_blocks * 512,
               "date": time.strftime("%Y-%m-%d"), "commit": commit.stdout.strip() or "unknown",
               "host_cpus": os.cpu_count()}
    if a.build_seconds is not None:
        results["image_build_s"] = a.build_seconds

    pki, dirs = host_dirs(work, a.farm, a.deb, a.repo if a.overlay else "", a.layout)
    results["layout"] = a.layout
    images = {}
    for name, d in dirs.items():
        img = os.path.join(work, f"{name}.img")
        t = time.monotonic()
        run([os.path.join(a.repo, "image", "farm", "provision"), "--output", img, a.image, d])
        farmvm.serial_console_entry(img, work)
        log(f"{name}: provisioned copy {img} in {time.monotonic() - t:.1f} s")
        images[name] = img
    kiosk_dir, kiosk_toml = kiosk_config(a.kiosk, work, pki)
    r = subprocess.run([a.kiosk, "--config", kiosk_toml, "--check-config"], stdout=subprocess.PIPE,
                       stderr=subprocess.STDOUT, text=True)
    if not fails.check(r.returncode == 0, "the host kiosk's configuration validates"):
        log(r.stdout)
        return 1

    net = farmvm.Netns(f"mogao-farmtest-{os.getpid()}",
                       [f"{V6}1/64", f"{V4}1/24", f"{OUTSIDE_V6}/64", f"{OUTSIDE_V4}/24"], len(HOSTS))
    vms = {}
    try:
        net.up()
        t_start = time.monotonic()
        for i, (name, (_, mac, mem)) in enumerate(HOSTS.items()):
            vms[name] = farmvm.start_vm(net, f"tap{i}", mac, images[name], mem, os.path.join(work, name), name)
        serials = {name: vm.serial for name, vm in vms.items()}
        admin, render = serials["farm-admin"], serials["farm-render2"]
        alive = lambda: all(vm.proc.poll() is None for vm in vms.values())

        for name, s in serials.items():
            t, _ = s.wait(r"start ", a.timeout, alive)
            if not fails.check(t is not None, f"{name}: the self-test started (serial marker)"):
                raise RuntimeError(f"{name} did not boot")
            results[f"{name}_qemu_start_to_selftest_s"] = round(t - t_start, 1)
        # The technician's install on each host (selftest.sh install_package), then the admin's
        # start once farm-render2 answers its ssh login with the package there.
        for name, s in serials.items():
            text = expect_ok(s, "package-installed", 600, alive, fails,
                             f"{name}: apt install ./mogao-farm_*.deb (offline, stock Debian 12)")
            if text:
                results[f"{name}_package_install_s"] = float(farmvm.fields(text)["seconds"])
            expect_ok(s, "package-state", 60, alive, fails,
                      f"{name}: the package made user mogao-farm (971, home /var/lib/mogao-farm) and enabled, "
                      "did not start, the unit")
            expect_ok(s, "site-configured", 120, alive, fails, f"{name}: the site's files written after it")
        expect_ok(admin, "render-host-answers", 700, alive, fails,
                  "farm-admin: farm-render2 answers the farm user's ssh login with mogao-farm installed")
        t_ready, text = admin.wait(r"(ok|FAIL) farm-ready", a.timeout, alive)
        ok = fails.check(text is not None and text.startswith("ok"),
                         f"farm-admin: mogao-farm.service active (READY): {text}")
        if ok:
            kv = farmvm.fields(text)
            results["host_qemu_start_to_farm_ready_s"] = round(t_ready - t_start, 1)
            results["guest_boot_to_farm_ready_s"] = round(int(kv["ready_us"]) / 1e6, 1)
            results["guest_exec_to_farm_ready_s"] = round((int(kv["ready_us"]) - int(kv["exec_us"])) / 1e6, 1)
            # The launcher (systemd/mogao-farm-launch, mpirun its child); ps shows 15 characters of its name.
            fails.check(kv.get("user") == "mogao-farm" and kv.get("main") == "mogao-farm-launch"[:15],
                        f"farm-admin: the unit's main process is mogao-farm-launch as mogao-farm "
                        f"(main={kv.get('main')} user={kv.get('user')})")
            # Restarts before READY are normal when the admin boots before the render hosts' sshd
            # is up (mpirun fails, Restart=on-failure tries again): recorded, not a failure.
            results["restarts_before_ready"] = int(kv.get("restarts", -1))
        _, text = admin.wait(r"ok ranks ", 120, alive)
        admin_ranks = farmvm.parse_ranks(text or "")
        results["admin_ranks"] = admin_ranks
        expected = ["0", "1"] if a.layout == "both" else [str(r) for r in range(RANKS)]
        fails.check(sorted(r["rank"] for r in admin_ranks) == expected and
                    all(r["uid"] == "971" and r["seccomp"] == "2" and r["nnp"] == "1" for r in admin_ranks),
                    f"farm-admin: ranks {expected} run as mogao-farm (uid 971) with seccomp and no_new_privs: "
                    f"{admin_ranks}")
        _, text = render.wait(r"(ok|FAIL|skip) rank-running", 300, alive)
        render_ranks = farmvm.parse_ranks(text or "")
        results["render2_ranks"] = render_ranks
        a.layout == "admin-only" or fails.check(text is not None and text.startswith("ok")
                                                and [r["rank"] for r in render_ranks] == ["2"]
                    and "parent=orted" in text and "user=mogao-farm" in text,
                    f"farm-render2: rank 2 runs there, under orted, as mogao-farm (started over ssh): {text}")
        if a.layout == "both":
            # The admin's own word that the job spans both hosts: rank 0 serves with 2 render ranks.
            serving = [m for _, m in admin.marks if m.startswith("log ") and " serving " in m and "render ranks" in m]
            fails.check(any("(2 render ranks" in m for m in serving),
                        f"farm-admin: the farm serves with 2 render ranks, one of them on farm-render2: {serving[-1:]}")
        _, text = admin.wait(r"security-online ", 60, alive)
        if text:
            m = re.search(r"exposure level.*?:\s*([\d.]+)", text)
            results["security_online_exposure"] = float(m.group(1)) if m else text
        admin.wait(r"farm-ready$", 60, alive)
        render.wait(r"rank-ready$", 120, alive)
        for name, s in serials.items():
            listen = [m.split()[1:] for _, m in s.marks if m.startswith("listen ")]
            results[f"{name}_listening"] = [" ".join(x) for x in listen]
            bad = farmvm.unexpected_listeners(listen, PORT)
            fails.check(not bad, f"{name}: listening sockets are the farm port, sshd and Open MPI's port ranges "
                                 f"only ({len(listen)} sockets; unexpected: {bad})")

        check_packet_filter(net, serials, fails, results)

        # --- the host's kiosk, headless, as the appliance ---------------------------------------
        if ok:
            t_kiosk = time.time()
            stats_file = os.path.join(kiosk_dir, "stats.json")
            r = net.run([a.kiosk, "--config", kiosk_toml, "--frames", str(KIOSK_FRAMES),
                         "--duration-s", str(KIOSK_TIMEOUT_S),
                         "--stats", stats_file, "--dump-content", os.path.join(kiosk_dir, "content")],
                        os.path.join(kiosk_dir, "kiosk.log"), timeout=KIOSK_TIMEOUT_S + 60)
            log(f"host kiosk exited {r} after {time.time() - t_kiosk:.1f} s")
            kres = farmvm.kiosk_results(kiosk_dir, stats_file, t_kiosk, a.image_tool)
            results.update(kres)
            fails.check(kres.get("kiosk_connected_s") is not None,
                        f"host kiosk connected to [{V6}10]:{PORT} over IPv6 + mutual TLS "
                        f"({kres.get('kiosk_connected_s')} s)")
            fails.check(kres.get("kiosk_frames", 0) >= 1,
                        f"host kiosk presented farm frames: {kres.get('kiosk_frames', 0)} "
                        f"(first after {kres.get('kiosk_first_frame_s')} s)")
            fails.check(kres.get("content_mean", 0) > 10 and kres.get("content_dark", 1) < 0.5,
                        f"the farm's frame is not black: mean {kres.get('content_mean')}, "
                        f"dark fraction {kres.get('content_dark')}")
            if "output_mean" in kres:
                fails.check(kres["output_mean"] > 10, f"the kiosk's output PNG is lit: mean {kres['output_mean']}")
        vms["farm-admin"].tell("kiosk-done")

        # --- watchdog ----------------------------------------------------------------------------
        expect_ok(admin, "watchdog-pinged", 300, alive, fails,
                  "farm-admin: up without restarts for longer than WatchdogSec (the admin rank's pings arrive)")
        text = expect_ok(admin, "watchdog-restart", 600, alive, fails,
                         "farm-admin: WatchdogSec killed the SIGSTOPped admin rank and the farm restarted")
        if text:
            kv = farmvm.fields(text)
            results["watchdog_stop_to_active_again_s"] = float(kv["seconds"])
            results["watchdog_stop_to_kill_s"] = float(kv["kill_after_s"])
        vms["farm-render2"].tell("watchdog-done")
        _, text = render.wait(r"(ok|FAIL|skip) rank-restarted", 300, alive)
        a.layout == "admin-only" or fails.check(text is not None and text.startswith("ok"),
                                                f"farm-render2: a new rank replaced the old one: {text}")
        if a.host_loss and a.layout == "both":
            render.wait(r"done ", 300, alive)  # farm-render2's own self-test ends before it is lost
            _, mac, mem = HOSTS["farm-render2"]
            host_loss.run(net, vms, ("farm-render2", "tap1", mac, mem), images["farm-render2"], work, a.kiosk,
                          kiosk_toml, results, fails)
        vms["farm-admin"].tell("finish")
        for name, s in serials.items():
            t_done, _ = s.wait(r"done ", 300, alive)
            fails.check(t_done is not None, f"{name}: the self-test finished")
            for _, mark in s.marks:
                if mark.startswith("FAIL "):
                    fails.check(False, f"{name}: {mark[5:]}")
                elif mark.split()[:2] in (["ok", "no-failed-units"], ["ok", "no-passwords"], ["ok", "sshd-active"]):
                    fails.check(True, f"{name}: {mark[3:]}")
    except Exception as e:  # noqa: BLE001 - report, then fail below
        fails.check(False, f"test aborted: {type(e).__name__}: {e}")
    finally:
        for vm in vms.values():
            farmvm.stop_vm(vm)
        net.down()
    results["failures"] = fails.items
    results["test_seconds"] = round(time.monotonic() - farmvm.T0, 1)
    log("results: " + json.dumps(results))
    if a.results:
        with open(a.results, "w") as f:
            json.dump(results, f, indent=2)
    if fails.items:
        for name, vm in vms.items():
            log(f"{name} serial console (last lines):\n" + vm.serial.tail(60))
        log(f"{len(fails.items)} check(s) failed; logs in {work}")
        return 1
    for img in images.values():   # ~1 GB each; logs stay
        if os.path.exists(img):
            os.remove(img)
    log("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
