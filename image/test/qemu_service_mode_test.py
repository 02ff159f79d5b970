#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The locked appliance's service mode end to end in QEMU, without a shell: signed requests on USB
sticks plugged into the running appliance, their results read back from the sticks.

    qemu_service_mode_test.py --image mogao-kiosk.img --repo SRC --kiosk BIN --farm BIN
                              --calibrate BIN --rig-film BIN [--work DIR] [--accel tcg|kvm]

A copy of the image is provisioned by image/provision with a test PKI, a kiosk.toml on KMS with an
installed calibration (OLD: the captures below calibrated on the host with --fit-screen), the site
file rigs/qemu.toml, calibrate.args and the museum's public key (mogao-service-request keygen). Its
loader entry only adds console options (the journal on the serial port, which is how the host sees
that a request is done): no self-test script, no shell. QEMU as in the other image tests (q35,
OVMF, virtio-gpu with 3 outputs, TCG) plus an xHCI controller; each stick is a FAT image
(mkfs.vfat, mtools: label MOGAO-SVC) hot-plugged with QMP (device_add usb-storage) and unplugged
once the guest's journal says it can be removed. The camera is the one simulated part, as in
qemu_powercut_test.py: mogao-rig-film films the patterns of rigs/qemu.toml at half scale on the
host, and the captures travel on the stick with the request (captures_sha256 signed with it).

One boot, in order (each printed; any failure fails the test):
  1. calibrate (captures on the stick): result.toml outcome "done", mogao-calibrate exit 0, the
     installed calibration changed, the kiosk active again; the text console shows the run on the
     wall while the kiosk is stopped (screendump of output 0 not black);
  2. calibrate from captures with one pattern's image missing (signed as they are): outcome
     "failed", the reason names the missing capture and says the last good calibration is kept, the
     installed calibration unchanged, the kiosk active again;
  3. the same stick's request signed for "status" and then edited (action changed): refused for its
     signature;
  4. the first request again (a replay): refused for its serial;
  5. status: the status panel toggled on and off (the kiosk's journal says so; it draws the panel
     over the show, not over its connecting card, and no farm runs here), outcome "done"; the
     kiosk's status file on the stick names the installed calibration, loaded after request 1, and
     so does the status page (status.html) the appliance made from it;
  6. logs: the journal, the status file and the installed calibration come back on the stick; the
     MPCDI is byte-identical to what request 1 installed (2-5 changed nothing), its last good copy
     is OLD, and it is within the calibration's geometry goals against the rig's ground truth
     (mogao-rig-film measure: mean <= 0.3, p95 <= 0.8 projector pixels of the half-scale rig); the
     kiosk was stopped once per calibrate request only; every output lit by the kiosk.
--live: request 1 calibrates on the guest's KMS outputs with the virtual rig's simulated camera
(calibrate.args: --outputs kms --camera rig:/etc/mogao/site.toml, as image_qemu_boot runs it; its
patterns on the wall) instead of captures on the stick; a manual run, minutes more under TCG, on an image
built with `image/build --calibrate build/kiosk/calibrate/mogao-calibrate-sim` (the shipped
mogao-calibrate has no rig camera).
An unsigned request and the other refusals are checked on the host (service_mode_requests), not
here: each stick costs about 15 s under TCG.
Exit 77 (skip) with a message when QEMU, OVMF, mtools, mkfs.vfat, openssl or the image are missing.
"""
import argparse
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

from qemu_common import IMAGE_ENTRY, T0, Failures, log, set_name, stop_qemu  # noqa: E402 (this folder)
from qemu_boot_test import (MODES, OUTPUTS, OVMF_CODE, OVMF_VARS, Qmp, install_selftest_entry,  # noqa: E402
                            ppm_stats, require_qemu, run)
from qemu_powercut_test import RIG, SCALE, host_calibration  # noqa: E402

SKIP = 77
LABEL = "MOGAO-SVC"
STICK_MIB = 48
GOAL_MEAN_PX, GOAL_P95_PX = 0.3, 0.8   # the calibration's geometry goals (docs/on-site-calibration.md)


def skip(msg):
    print(f"SKIP: {msg}", flush=True)
    sys.exit(SKIP)


class Journal:
    """Follows the serial log (the guest's journal, forwarded to the console) from a cursor on."""

    def __init__(self, path, proc):
        self.path, self.proc, self.pos = path, proc, 0

    def text(self):
        try:
            with open(self.path, "rb") as f:
                return f.read().decode("utf-8", "replace")
        except FileNotFoundError:
            return ""

    def wait(self, pattern, timeout):
        """The first match of `pattern` after the cursor; moves the cursor past it. None on timeout."""
        rx = re.compile(pattern)
        deadline = time.monotonic() + timeout
        while True:
            m = rx.search(self.text(), self.pos)
            if m:
                self.pos = m.end()
                return m
            if time.monotonic() > deadline or self.proc.poll() is not None:
                return None
            time.sleep(0.5)


def tool(a, *args, **kw):
    return run([os.path.join(a.repo, "kiosk", "service_mode", "mogao-service-request"), *args], **kw)


def provision(a, work, env):
    """The test copy, provisioned; returns (image, signing key, OLD mpcdi, captures folder)."""
    pki, cfg = os.path.join(work, "pki"), os.path.join(work, "config")
    for d in (pki, cfg, os.path.join(work, "keys")):
        shutil.rmtree(d, ignore_errors=True)
    run([a.farm, "pki", "init-ca", "--dir", pki])
    run([a.farm, "pki", "issue-appliance", "--dir", pki, "--name", "museum-1"])
    os.makedirs(os.path.join(cfg, "pki"))
    for f in ("ca.pem", "appliance-museum-1.pem", "appliance-museum-1.key"):
        shutil.copy(os.path.join(pki, f), os.path.join(cfg, "pki", f))
    site = os.path.join(a.repo, RIG)
    captures = os.path.join(work, "captures")
    shutil.rmtree(captures, ignore_errors=True)
    run([a.calibrate, "patterns", "--site", site, "--scale", str(SCALE), "--out", captures])
    run([a.rig_film, "--rig", site, "--scale", str(SCALE), "film", "--patterns", captures])
    old_mpcdi, old_models = host_calibration(a, captures, os.path.join(work, "old-calibration"), ["--fit-screen"])
    shutil.copy(old_mpcdi, os.path.join(cfg, "screen.mpcdi"))
    shutil.copy(old_models, os.path.join(cfg, "screen.models.json"))
    shutil.copy(site, os.path.join(cfg, "site.toml"))
    with open(os.path.join(cfg, "calibrate.args"), "w") as f:  # --outputs/--camera: dropped with captures
        f.write("# the on-site calibration's options (docs/service-mode.md)\n")
        if a.live:  # the KMS outputs filmed by the rig's SIMULATED camera, as image_qemu_boot runs it
            f.write("--outputs\nkms\n--camera\nrig:/etc/mogao/site.toml\n--no-colour\n--no-bow\n--settle-ms\n0\n"
                    "--drop-frames\n0\n")
        else:
            f.write(f"--outputs\nkms\n--scale\n{SCALE}\n--camera-transfer\nlinear\n--no-bow\n")
    overrides = ['farm.endpoint="[fec0::2]:48615"', 'farm.ca="pki/ca.pem"', 'farm.cert="pki/appliance-museum-1.pem"',
                 'farm.key="pki/appliance-museum-1.key"', "display.rate_hz=2", 'outputs.backend="kms"',
                 'calibration.source="screen.mpcdi"', 'quality.content="480x270"', "stats.file=",
                 'stats.status_file="/run/mogao/kiosk-status.json"', 'status.on_wall="on_demand"']
    printed = run([a.kiosk, "--print-config", *overrides]).stdout
    with open(os.path.join(cfg, "kiosk.toml"), "w") as f:
        f.write("# written by image/test/qemu_service_mode_test.py\n" + printed)
    tool(a, "keygen", "--out", os.path.join(work, "keys"))
    shutil.copy(os.path.join(work, "keys", "service-key.pem"), os.path.join(cfg, "service-key.pem"))
    img = os.path.join(work, "service-mode.img")
    run(["cp", "--sparse=always", a.image, img])
    run([os.path.join(a.repo, "image", "provision"), "--kiosk", a.kiosk, img, cfg])
    esp = f"{img}@@1M"
    entry = run(["mtype", "-i", esp, IMAGE_ENTRY], env=env).stdout
    # loglevel=3 stays: the wall's text console shows the service mode's lines, not the kernel's.
    options = re.sub(r"\b(quiet|systemd.show_status=\S+)\b", "", re.search(r"^options (.*)$", entry, re.M).group(1))
    extra = ["console=tty0", "console=ttyS0,115200", "systemd.show_status=true",
             "systemd.journald.forward_to_console=1",
             *[f"video=Virtual-{i + 1}:{MODES[i][0]}x{MODES[i][1]}e" for i in range(1, OUTPUTS)]]
    install_selftest_entry(work, esp, "mogao (QEMU service-mode test: console on the serial port)", options, extra, env)
    return img, os.path.join(work, "keys", "service-signing.key"), old_mpcdi, captures


def make_stick(a, work, name, env, key, action, serial, captures=None, tamper=None, extra=()):
    """A FAT stick image holding a request signed by `key` (then tampered with)."""
    stage = os.path.join(work, f"stick-{name}")
    shutil.rmtree(stage, ignore_errors=True)
    os.makedirs(stage)
    args = ["sign", "--key", key, "--action", action, "--stick", stage, "--serial", str(serial), *extra]
    if captures:
        shutil.copytree(captures, os.path.join(stage, "captures"))
        args += ["--captures", "captures"]
    tool(a, *args)
    req = os.path.join(stage, "request.toml")
    if tamper:
        with open(req) as f:
            text = f.read()
        with open(req, "w") as f:
            f.write(text.replace(*tamper))
    img = os.path.join(work, f"stick-{name}.img")
    if os.path.exists(img):
        os.remove(img)
    run(["truncate", "-s", f"{STICK_MIB}M", img])
    run(["mkfs.vfat", "-n", LABEL, img])
    run(["mcopy", "-s", "-i", img, *[os.path.join(stage, n) for n in sorted(os.listdir(stage))], "::/"], env=env)
    return img


def read_stick(img, name, env):
    """A file of the stick image (None when missing)."""
    r = subprocess.run(["mtype", "-i", img, f"::/{name}"], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, env=env)
    return r.stdout if r.returncode == 0 else None


def result_of(img, env):
    text = (read_stick(img, "result.toml", env) or b"").decode()
    return dict(re.findall(r'^(\w+) = "(.*)"$', text, re.M))


def plug(qmp, journal, img, n, timeout, during=None):
    """Hot-plugs stick n, waits until the guest says it can be removed, unplugs it. `during`:
    (pattern, function): the function is called once the guest's journal matches the pattern."""
    qmp.cmd("blockdev-add", driver="raw", **{"node-name": f"stick{n}"}, file={"driver": "file", "filename": img})
    qmp.cmd("device_add", driver="usb-storage", id=f"usb{n}", drive=f"stick{n}", bus="xhci.0")
    t = time.monotonic()
    if during is not None and journal.wait(during[0], timeout):
        during[1]()
    done = journal.wait(r"mogao-service: done: the stick can be removed", timeout)
    seconds = time.monotonic() - t
    journal.wait(r"mogao-service@\S+\.service: (Deactivated successfully|Failed with result)", 60)
    qmp.cmd("device_del", id=f"usb{n}")
    deadline = time.monotonic() + 30
    while not any(e.get("event") == "DEVICE_DELETED" and e.get("data", {}).get("device")
                  == f"usb{n}" for e in qmp.events):
        if time.monotonic() > deadline:
            break
        qmp.poll_events(0.5)
    qmp.cmd("blockdev-del", **{"node-name": f"stick{n}"})
    return done is not None, seconds


def screendump(qmp, work, tag, head):
    path = os.path.join(work, f"{tag}-head{head}.ppm")
    qmp.cmd("screendump", filename=path, device="gpu0", head=head)
    return ppm_stats(path)


def lit_fraction(path):
    """Fraction of pixels brighter than code 64 in a P6 PPM (text on a black console)."""
    with open(path, "rb") as f:
        data = f.read()
    parts = data.split(b"\n", 3)
    pixels = parts[3]
    lit = sum(1 for i in range(0, len(pixels) - 2, 3 * 7) if pixels[i] > 64 or pixels[i + 1] > 64)
    return lit / max(1, len(pixels) // (3 * 7))


def qemu_command(qemu, a, work, img):
    vars_fd = os.path.join(work, "OVMF_VARS.fd")
    shutil.copy(OVMF_VARS, vars_fd)
    return [qemu, "-nodefaults", "-machine", "q35", "-m", "2048", "-smp", "2",
            "-accel", "kvm" if a.accel == "kvm" else "tcg", "-cpu", "host" if a.accel == "kvm" else "max",
            "-drive", f"if=pflash,format=raw,readonly=on,file={OVMF_CODE}",
            "-drive", f"if=pflash,format=raw,file={vars_fd}",
            "-drive", f"if=virtio,format=raw,file={img}",
            "-device", f"virtio-gpu-pci,id=gpu0,max_outputs={OUTPUTS},xres={MODES[0][0]},yres={MODES[0][1]},edid=off",
            "-device", "qemu-xhci,id=xhci",
            "-netdev", "user,id=n0,ipv4=off,ipv6=on", "-device", "virtio-net-pci,netdev=n0",
            "-display", "none", "-serial", f"file:{os.path.join(work, 'serial.log')}",
            "-qmp", f"unix:{os.path.join(work, 'qmp.sock')},server=on,wait=off"]


def check_logs(a, work, qmp, journal, fails, env, stick, installed_sha, old_mpcdi, results):
    """The logs request, after the others: the calibration as the calibrate request left it."""
    ok, secs = plug(qmp, journal, stick, 6, a.timeout)
    rl = result_of(stick, env)
    fails.check(ok and rl.get("outcome") == "done", f"logs: {rl.get('reason')} in {secs:.0f} s")
    mpcdi = read_stick(stick, "logs/screen.mpcdi", env) or b""
    last_good = read_stick(stick, "logs/screen.mpcdi.last-good", env) or b""
    journal_text = (read_stick(stick, "logs/journal.txt", env) or b"").decode(errors="replace")
    fails.check(hashlib.sha256(mpcdi).hexdigest() == installed_sha,
                "the calibration is byte-identical to what the calibrate request installed (the refused ones "
                "changed nothing)")
    with open(old_mpcdi, "rb") as f:
        fails.check(last_good == f.read(), "its last good copy is the calibration installed before")
    fetched = os.path.join(work, "fetched-screen.mpcdi")
    with open(fetched, "wb") as f:
        f.write(mpcdi)
    m = re.search(r"geometry mean ([0-9.]+) p95 ([0-9.]+)", run([a.rig_film, "--rig", os.path.join(a.repo, RIG),
                  "--scale", str(1.0 if a.live else SCALE), "measure", "--mpcdi", fetched]).stdout) if mpcdi else None
    results["geometry_px"] = [float(m.group(1)), float(m.group(2))] if m else None
    fails.check(m is not None and float(m.group(1)) <= GOAL_MEAN_PX and float(m.group(2)) <= GOAL_P95_PX,
                f"the new calibration against the rig's ground truth: {results['geometry_px']} (mean, p95 px)")
    stops = len(re.findall(r"Stopping mogao-kiosk\.service", journal_text))
    fails.check(len(journal_text) > 1000 and stops == 2,
                f"logs: the journal on the stick ({len(journal_text)} bytes); the kiosk stopped {stops} time(s) "
                "(once per calibrate request)")
    lit = [screendump(qmp, work, "after", h) for h in range(OUTPUTS)]
    fails.check(all(mean > 10 for _, _, mean, _ in lit),
                f"every output lit by the kiosk after the requests (mean codes {[round(x[2], 1) for x in lit]})")


def check_requests(a, work, proc, fails, env, key, old_mpcdi, captures, results):
    """The requests of the module's docstring, in one boot."""
    journal = Journal(os.path.join(work, "serial.log"), proc)
    qmp = Qmp(os.path.join(work, "qmp.sock"))
    t0 = time.monotonic()
    ready = journal.wait(r"Started .*mogao kiosk", a.timeout)
    results["boot_to_kiosk_s"] = round(time.monotonic() - t0, 1)
    if not fails.check(ready is not None, f"the kiosk started ({results['boot_to_kiosk_s']} s after QEMU)"):
        return
    serial = int(time.time())
    # A calibration that must fail: the captures with one pattern's image missing (signed as they are).
    broken = os.path.join(work, "captures-broken")
    shutil.rmtree(broken, ignore_errors=True)
    shutil.copytree(captures, broken)
    with open(os.path.join(broken, "captures.json")) as f:
        os.remove(os.path.join(broken, json.load(f)["captures"]["p0-columns-bit00"]))
    sticks = {
        "calibrate": make_stick(a, work, "calibrate", env, key, "calibrate", serial + 1, None if a.live else captures,
                                extra=("--hold-s", "3")),
        "broken": make_stick(a, work, "broken", env, key, "calibrate", serial + 2, broken, extra=("--hold-s", "1")),
        "tampered": make_stick(a, work, "tampered", env, key, "status", serial + 3,
                               tamper=('action = "status"', 'action = "calibrate"')),
        "status": make_stick(a, work, "status", env, key, "status", serial + 4, extra=("--show-s", "1")),
        "logs": make_stick(a, work, "logs", env, key, "logs", serial + 5),
    }
    replay = os.path.join(work, "stick-replay.img")
    shutil.copy(sticks["calibrate"], replay)
    wall = {}

    def during():
        time.sleep(2)
        screendump(qmp, work, "calibrating", 0)
        wall["lit"] = lit_fraction(os.path.join(work, "calibrating-head0.ppm"))

    plugged_utc = time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())
    ok, secs = plug(qmp, journal, sticks["calibrate"], 1, a.timeout,
                    (r"mogao-service: calibration: mogao-calibrate ", during))
    r = result_of(sticks["calibrate"], env)
    results["calibrate_request_s"] = round(secs, 1)
    fails.check(ok and r.get("outcome") == "done" and r.get("calibrate_exit") == "0",
                f"calibrate: done in {secs:.0f} s ({r})")
    fails.check(r.get("calibration_before") != r.get("calibration_after") and r.get("calibration_after", "none")
                != "none",
                "calibrate: the installed calibration changed")
    fails.check(r.get("kiosk") == "active", f"calibrate: the kiosk active again ({r.get('kiosk')})")
    fails.check(wall.get("lit", 0) > 0.002, f"calibrate: its output on the wall while the kiosk is stopped "
                f"(output 0 lit fraction {wall.get('lit', 0):.4f})")
    log_text = (read_stick(sticks["calibrate"], "calibrate.log", env) or b"").decode(errors="replace")
    fails.check("calibration" in log_text, f"calibrate: calibrate.log on the stick ({len(log_text)} bytes)")

    # A failed calibration keeps the installed one (byte-identical) and brings the show back on it.
    ok, secs = plug(qmp, journal, sticks["broken"], 2, a.timeout)
    rb = result_of(sticks["broken"], env)
    results["failed_calibrate_request_s"] = round(secs, 1)
    fails.check(ok and rb.get("outcome") == "failed" and "missing" in rb.get("reason", "")
                and "last good calibration is kept" in rb.get("reason", ""),
                f"failing calibrate: failed, naming the missing capture, in {secs:.0f} s ({rb.get('reason')})")
    fails.check(rb.get("calibration_before") == rb.get("calibration_after") == r.get("calibration_after"),
                "failing calibrate: the installed calibration unchanged (the first calibrate's)")
    fails.check(rb.get("kiosk") == "active", f"failing calibrate: the kiosk active again ({rb.get('kiosk')})")

    for n, (name, img, want) in enumerate((("tampered", sticks["tampered"], "bad signature"),
                                           ("replay", replay, "used already")), start=3):
        ok, secs = plug(qmp, journal, img, n, a.timeout)
        rr = result_of(img, env)
        fails.check(ok and rr.get("outcome") == "refused" and want in rr.get("reason", ""),
                    f"{name}: refused ({rr.get('reason')}) in {secs:.0f} s")

    ok, secs = plug(qmp, journal, sticks["status"], 5, a.timeout)
    rs = result_of(sticks["status"], env)
    fails.check(ok and rs.get("outcome") == "done", f"status: {rs.get('reason')} in {secs:.0f} s")
    # The kiosk draws the panel over the show, not over its connecting card (no farm here): the
    # kiosk's own journal line says the toggle reached it.
    fails.check(re.search(r"SIGUSR2: status panel shown on the wall", journal.text()) is not None,
                "status: the kiosk toggled its status panel on (its journal)")
    try:
        st = json.loads(read_stick(sticks["status"], "kiosk-status.json", env) or b"{}")
    except ValueError:
        st = {}
    cal = st.get("calibration", {})
    fails.check(cal.get("source") == "/etc/mogao/screen.mpcdi" and cal.get("last_error") == "" and cal.get("refused")
                == 0
                and cal.get("loaded_utc", "") > plugged_utc,
                f"status: the kiosk's status file on the stick: running on the installed calibration, loaded "
                f"{cal.get('loaded_utc')} (the calibrate stick went in at {plugged_utc}), no error")
    # The technician's status page, made on the appliance from the same status file (docs/monitoring.md).
    page = (read_stick(sticks["status"], "status.html", env) or b"").decode("utf-8", "replace")
    fails.check(rs.get("status_page") == "status.html" and "/etc/mogao/screen.mpcdi" in page
                and "<html" in page.lower(),
                f"status: status.html on the stick names the installed calibration (result: {rs.get('status_page')}, "
                f"{len(page)} characters)")

    check_logs(a, work, qmp, journal, fails, env, sticks["logs"], r.get("calibration_after"), old_mpcdi, results)


def main():
    set_name("service-mode")
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--image", required=True)
    ap.add_argument("--repo", required=True)
    for t in ("kiosk", "farm", "calibrate", "rig-film"):
        ap.add_argument(f"--{t}", required=True, help=f"host mogao-{t} (prepares the files)")
    ap.add_argument("--live", action="store_true",
                    help="calibrate on the KMS outputs with the rig's simulated camera instead of captures on the "
                         "stick (minutes more under TCG; not in CI)")
    ap.add_argument("--work", default="")
    ap.add_argument("--accel", default=os.environ.get("MOGAO_IMAGE_QEMU_ACCEL", "tcg"), choices=["tcg", "kvm"])
    ap.add_argument("--timeout", type=float, default=float(os.environ.get("MOGAO_IMAGE_BOOT_TIMEOUT", "900")))
    a = ap.parse_args()
    qemu = require_qemu(a.image)
    for t in ("mkfs.vfat", "mcopy", "mtype", "openssl"):
        if shutil.which(t) is None:
            skip(f"{t} not found (apt-get install dosfstools mtools openssl)")
    if os.geteuid() != 0:
        skip("needs root (image/provision writes files owned by the kiosk user)")
    work = a.work or tempfile.mkdtemp(prefix="mogao-qemu-service-")
    os.makedirs(work, exist_ok=True)
    for name in ("serial.log", "qmp.sock"):
        if os.path.exists(os.path.join(work, name)):
            os.remove(os.path.join(work, name))
    env = dict(os.environ, MTOOLS_SKIP_CHECK="1")
    fails = Failures()
    results = {}
    img, key, old_mpcdi, captures = provision(a, work, env)
    results["prepare_s"] = round(time.monotonic() - T0, 1)
    cmd = qemu_command(qemu, a, work, img)
    log("starting QEMU: " + " ".join(cmd))
    with open(os.path.join(work, "qemu.log"), "w") as qemu_log:
        proc = subprocess.Popen(cmd, stdout=qemu_log, stderr=subprocess.STDOUT)
        try:
            check_requests(a, work, proc, fails, env, key, old_mpcdi, captures, results)
        except Exception as e:  # noqa: BLE001 - report, then fail below
            fails.check(False, f"test aborted: {type(e).__name__}: {e}")
        finally:
            stop_qemu(proc)
    results["test_s"] = round(time.monotonic() - T0, 1)
    log(f"figures: {results}")
    if fails.items:
        tail = "\n".join(Journal(os.path.join(work, "serial.log"), proc).text().splitlines()[-80:])
        log("serial console (last lines):\n" + tail)
        log(f"{len(fails.items)} check(s) failed; logs in {work}")
        return 1
    os.remove(img)
    log("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
