#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""A/B updates of the appliance end to end in QEMU, without a shell: signed update bundles on USB
sticks through the service mode, a good update that boots, a bad one that rolls back, and the
calibration on the configuration partition byte-identical after both (docs/updates.md).

    qemu_update_test.py --image mogao-kiosk.img --repo SRC --kiosk BIN --farm BIN --update-key KEY
                        [--work DIR] [--accel tcg|kvm] [--results FILE]

Bundles are made by image/bundle from the image image_build made (no second image is built):
  GOOD: the image's root with its version marker changed ("mogao-kiosk update-test good");
  BAD:  the same root whose /usr/bin/mogao-kiosk is a script that exits 1 (a broken build: the kiosk
        never reports READY), version "mogao-kiosk update-test bad", --tries 1. The product default
        is 3 tries; one keeps the test's failed boots to one (each costs a boot under TCG), the
        mechanism is the same (systemd-boot counts down, the entry with no tries left loses).
  WRONG: a small bundle signed by another key than the one the image trusts.
KEY is the private key whose public key image_build put into the image (image/bundle keygen). A copy
of the image is provisioned (image/provision) with a test PKI, kiosk.toml, the calibration
screen.mpcdi (an ideal two-projector MPCDI of tests/fuzz/corpus) and the museum's service key; a
second provisioning without --wipe must be refused (the partition holds a configuration now). The
test copy's loader entry of slot a gets console options (the journal on the serial port, how the
host reads what happens); mogao-update carries them into the entries it writes. QEMU as in
qemu_service_mode_test.py (q35, OVMF, virtio-gpu, xHCI, TCG); one QEMU process for the whole
test, the guest's reboots included (its NVRAM and ESP keep systemd-boot's counters).

In order (each printed; any failure fails the test):
  1. slot a boots, the kiosk starts;
  2. the WRONG stick: refused for its signature (result.toml), nothing written;
  3. the GOOD stick: installed into slot b; the appliance reboots, systemd-boot tries slot b, the
     kiosk reports READY there, the boot assessment passes and systemd-bless-boot marks it good;
     the calibration's sha256 on the configuration partition is unchanged (read from the running
     guest's disk with debugfs -c);
  4. the BAD stick (on slot b): installed into slot a; the reboot tries it, the kiosk fails, the
     boot assessment fails and reboots, systemd-boot falls back to slot b (GOOD), whose kiosk
     starts and whose status line names the rolled-back update;
  5. a logs stick on the rolled-back appliance: the journal of the boot before (the bad root's, kept
     on the configuration partition, docs/image.md "Journal") comes back as
     logs/journal-previous-boot.txt (journalctl --boot=-1 in the guest) with that boot's lines
     ("running slot a: ... update-test bad", "boot assessment FAILED") and none of this boot's
     (the rollback line), which logs/journal.txt has;
  6. on the disk after QEMU: slot b's entry blessed, slot a's with no tries left, the calibration
     byte-identical (sha256) to the provisioned one; the configuration partition's journal/ (copied
     out after e2fsck -p) holds all 4 boots (the host's journalctl --list-boots) in no more than
     the image's SystemMaxUse.
Exit 77 (skip) with a message when QEMU, OVMF, mtools, mkfs.vfat, zstd or openssl are missing.
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
from qemu_boot_test import MODES, OVMF_CODE, OVMF_VARS, Qmp, require_qemu, run  # noqa: E402
from qemu_service_mode_test import LABEL, Journal, read_stick, result_of, skip, tool  # noqa: E402
from qemu_service_mode_test import make_stick as make_request_stick  # noqa: E402

OUTPUTS = 2            # the calibration's projectors
CONFIG_PART = 3        # image/lib/common.sh
CALIBRATION = "tests/fuzz/corpus/mpcdi/ideal-2.mpcdi"
JOURNAL_CONF = "image/rootfs/etc/systemd/journald.conf.d/50-mogao.conf"
BROKEN_KIOSK = "#!/bin/sh\necho 'mogao-kiosk: a broken build (image/test/qemu_update_test.py)' >&2\nexit 1\n"


def partition_offset(img, n):
    for line in run(["sfdisk", "--dump", img]).stdout.splitlines():
        if re.match(rf"^\S*{n} :", line):
            return int(re.search(r"start= *(\d+)", line).group(1)) * 512
    raise RuntimeError(f"{img} has no partition {n}")


def config_file_sha(img, path):
    """sha256 of a file on the configuration partition of the raw image (debugfs, read-only)."""
    r = subprocess.run(["debugfs", "-c", "-R", f"cat {path}", f"{img}?offset={partition_offset(img, CONFIG_PART)}"],
                       stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, check=True)
    return hashlib.sha256(r.stdout).hexdigest() if r.stdout else None


def esp_entries(img, env):
    out = run(["mdir", "-b", "-i", f"{img}@@1M", "::/loader/entries"], env=env).stdout
    return sorted(os.path.basename(x) for x in out.split())


def provision(a, work, env):
    """The test copy, provisioned; returns (image, service signing key, calibration sha256)."""
    pki, cfg = os.path.join(work, "pki"), os.path.join(work, "config")
    for d in (pki, cfg, os.path.join(work, "keys")):
        shutil.rmtree(d, ignore_errors=True)
    run([a.farm, "pki", "init-ca", "--dir", pki])
    run([a.farm, "pki", "issue-appliance", "--dir", pki, "--name", "museum-1"])
    os.makedirs(os.path.join(cfg, "pki"))
    for f in ("ca.pem", "appliance-museum-1.pem", "appliance-museum-1.key"):
        shutil.copy(os.path.join(pki, f), os.path.join(cfg, "pki", f))
    shutil.copy(os.path.join(a.repo, CALIBRATION), os.path.join(cfg, "screen.mpcdi"))
    overrides = ['farm.endpoint="[fec0::2]:48615"', 'farm.ca="pki/ca.pem"', 'farm.cert="pki/appliance-museum-1.pem"',
                 'farm.key="pki/appliance-museum-1.key"', "display.rate_hz=2", 'outputs.backend="kms"',
                 'calibration.source="screen.mpcdi"', 'quality.content="480x270"', "stats.file="]
    with open(os.path.join(cfg, "kiosk.toml"), "w") as f:
        f.write("# written by image/test/qemu_update_test.py\n" + run([a.kiosk, "--print-config", *overrides]).stdout)
    tool(a, "keygen", "--out", os.path.join(work, "keys"))
    shutil.copy(os.path.join(work, "keys", "service-key.pem"), os.path.join(cfg, "service-key.pem"))
    img = os.path.join(work, "update.img")
    run(["cp", "--sparse=always", a.image, img])
    provision_cmd = [os.path.join(a.repo, "image", "provision"), "--kiosk", a.kiosk, img, cfg]
    run(provision_cmd)
    with open(os.path.join(cfg, "screen.mpcdi"), "rb") as f:
        cal_sha = hashlib.sha256(f.read()).hexdigest()
    return img, provision_cmd, os.path.join(work, "keys", "service-signing.key"), cal_sha


def console_entry(img, env, work):
    """Slot a's entry of the test copy with the journal on the serial port (same name, so the
    generation order stays the image's)."""
    esp = f"{img}@@1M"
    entry = run(["mtype", "-i", esp, IMAGE_ENTRY], env=env).stdout
    options = re.search(r"^options (.*)$", entry, re.M).group(1)
    options = re.sub(r"\b(quiet|systemd.show_status=\S+)\b", "", options)
    extra = ["console=tty0", "console=ttyS0,115200", "systemd.show_status=true",
             "systemd.journald.forward_to_console=1",
             f"video=Virtual-2:{MODES[1][0]}x{MODES[1][1]}e"]
    entry = re.sub(r"^options .*$", "options " + " ".join(options.split() + extra), entry, flags=re.M)
    path = os.path.join(work, "mogao-1-a.conf")
    with open(path, "w") as f:
        f.write(entry)
    run(["mcopy", "-o", "-i", esp, path, IMAGE_ENTRY], env=env)


def bundles(a, work):
    """GOOD and BAD bundles from the image (image/bundle), and a small WRONG one."""
    bundle = os.path.join(a.repo, "image", "bundle")
    good, bad = os.path.join(work, "good.bundle"), os.path.join(work, "bad.bundle")
    run([bundle, "--image", a.image, "--key", a.update_key, "--out", good, "--version", "mogao-kiosk update-test good"])
    root = os.path.join(work, "bad-root.ext4")
    start = partition_offset(a.image, 2) // 512
    run(["dd", f"if={a.image}", f"of={root}", "bs=512", f"skip={start}", f"count={partition_sectors(a.image, 2)}",
         "conv=sparse", "status=none"])
    script = os.path.join(work, "broken-kiosk")
    with open(script, "w") as f:
        f.write(BROKEN_KIOSK)
    r = subprocess.run(["debugfs", "-w", "-f", "-", root],
                       input=f"rm /usr/bin/mogao-kiosk\nwrite {script} /usr/bin/mogao-kiosk\n"
                       "sif /usr/bin/mogao-kiosk mode 0100755\nsif /usr/bin/mogao-kiosk uid 0\nsif "
                       "/usr/bin/mogao-kiosk gid 0\n",
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, check=True)
    if re.search(r"(error|not found|cannot)", r.stdout, re.I):
        raise RuntimeError("debugfs: " + r.stdout)
    run([bundle, "--image", a.image, "--root", root, "--key", a.update_key, "--out", bad, "--tries", "1",
         "--version", "mogao-kiosk update-test bad"])
    os.remove(root)
    # WRONG: the shape of a bundle, signed by a key the image does not trust (refused at the signature).
    wrong_dir = os.path.join(work, "wrong")
    shutil.rmtree(wrong_dir, ignore_errors=True)
    os.makedirs(wrong_dir)
    run([bundle, "keygen", "--out", os.path.join(wrong_dir, "key")])
    for name in ("vmlinuz", "initrd.img", "root.img.zst"):
        with open(os.path.join(wrong_dir, name), "wb") as f:
            f.write(os.urandom(4096))
    run(["sh", "-c", f"cd {wrong_dir} && tar -xOf {good} manifest.toml > manifest.toml && "
         f"openssl pkeyutl -sign -inkey key/update-signing.key -rawin -in manifest.toml -out manifest.toml.sig && "
         f"tar -cf ../wrong.bundle manifest.toml manifest.toml.sig vmlinuz initrd.img root.img.zst"])
    return good, bad, os.path.join(work, "wrong.bundle")


def partition_sectors(img, n):
    for line in run(["sfdisk", "--dump", img]).stdout.splitlines():
        if re.match(rf"^\S*{n} :", line):
            return int(re.search(r"size= *(\d+)", line).group(1))
    raise RuntimeError(f"{img} has no partition {n}")


def make_stick(a, work, name, env, key, serial, bundle):
    """A FAT stick holding `bundle` and an update request for it signed by the museum's `key`."""
    stage = os.path.join(work, f"stick-{name}")
    shutil.rmtree(stage, ignore_errors=True)
    os.makedirs(stage)
    os.link(bundle, os.path.join(stage, "update.bundle"))
    tool(a, "sign", "--key", key, "--action", "update", "--stick", stage, "--serial", str(serial), "--bundle",
         "update.bundle")
    img = os.path.join(work, f"stick-{name}.img")
    if os.path.exists(img):
        os.remove(img)
    run(["truncate", "-s", f"{os.path.getsize(bundle) // (1 << 20) + 40}M", img])
    run(["mkfs.vfat", "-n", LABEL, img])
    run(["mcopy", "-s", "-i", img, *[os.path.join(stage, n) for n in sorted(os.listdir(stage))], "::/"], env=env)
    shutil.rmtree(stage)
    return img


def plug(qmp, journal, img, n, timeout):
    """Hot-plugs stick n, waits until the guest says it can be removed, unplugs it."""
    qmp.cmd("blockdev-add", driver="raw", **{"node-name": f"stick{n}"}, file={"driver": "file", "filename": img})
    qmp.cmd("device_add", driver="usb-storage", id=f"usb{n}", drive=f"stick{n}", bus="xhci.0")
    t = time.monotonic()
    done = journal.wait(r"mogao-service: done: the stick can be removed", timeout)
    seconds = time.monotonic() - t
    journal.wait(r"mogao-service@\S+\.service: (Deactivated successfully|Failed with result)", 15)
    qmp.cmd("device_del", id=f"usb{n}")
    deadline = time.monotonic() + 20
    while not any(e.get("event") == "DEVICE_DELETED" and e.get("data", {}).get("device")
                  == f"usb{n}" for e in qmp.events):
        if time.monotonic() > deadline:
            break
        qmp.poll_events(0.5)
    qmp.cmd("blockdev-del", **{"node-name": f"stick{n}"})
    return done is not None, seconds


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


def booted(journal, slot, timeout, kiosk=True):
    """Waits for a boot of `slot` (mogao-update's status line) and its kiosk starting; returns the
    status line. The journal's cursor stays after the status line (the lines of that boot follow)."""
    before = journal.pos
    m = journal.wait(rf"mogao-update: running slot {slot}: ([^\r\n]*)", timeout)
    if m is None:
        return None
    if not kiosk:
        return m.group(1)
    after_status = journal.pos
    journal.pos = before
    started = journal.wait(r"Started mogao-kiosk\.service", timeout)
    journal.pos = after_status
    return m.group(1) if started else None


def check_previous_boot_log(a, qmp, journal, fails, env, stick, results):
    """Step 5: the logs request after the rollback; the previous boot is the bad root's."""
    ok, secs = plug(qmp, journal, stick, 4, a.timeout)
    r = result_of(stick, env)
    results["logs_s"] = round(secs, 1)
    fails.check(ok and r.get("outcome") == "done", f"logs after the rollback: {r.get('reason')} in {secs:.0f} s")
    prev = (read_stick(stick, "logs/journal-previous-boot.txt", env) or b"").decode(errors="replace")
    this = (read_stick(stick, "logs/journal.txt", env) or b"").decode(errors="replace")
    ran = r"running slot a: [^\n]*update-test bad"
    failed = r"boot assessment FAILED: mogao-kiosk not READY on slot a"
    rolled = r"slot a: the update '[^']*update-test bad[^']*' failed its boot assessment"
    results["previous_boot_log_lines"] = prev.count("\n")
    fails.check(re.search(ran, prev) is not None and re.search(failed, prev) is not None
                and re.search(rolled, prev) is None,
                f"logs/journal-previous-boot.txt is the bad root's boot ({prev.count(chr(10))} lines; its "
                f"slot line and "
                f"failed assessment, not this boot's rollback line): {prev.strip().splitlines()[:1]}")
    fails.check(re.search(rolled, this) is not None and re.search(failed, this) is None,
                "logs/journal.txt is this boot's (the rollback line, not the failed assessment)")
    kept = re.search(r"mogao-journal: the journal is kept in [^\n]*", this)
    fails.check(kept is not None,
                f"this boot's journal is on the configuration partition: {kept.group(0) if kept else 'no such line'}")


def journal_on_disk(a, img, work, fails, results):
    """Step 6, the journal part: the configuration partition copied out, e2fsck -p (as the
    appliance's systemd-fsck), journal/ copied out with debugfs and read by the host's journalctl."""
    part, dump = os.path.join(work, "config.ext4"), os.path.join(work, "journal-dump")
    run(["dd", f"if={img}", f"of={part}", "bs=512", f"skip={partition_offset(img, CONFIG_PART) // 512}",
         f"count={partition_sectors(img, CONFIG_PART)}", "conv=sparse", "status=none"])
    subprocess.run(["e2fsck", "-p", part], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    shutil.rmtree(dump, ignore_errors=True)
    os.makedirs(dump)
    run(["debugfs", "-R", f"rdump /journal {dump}", part])
    files = [os.path.join(d, n) for d, _, names in os.walk(os.path.join(dump, "journal")) for n in names]
    used = sum(os.path.getsize(f) for f in files)
    with open(os.path.join(a.repo, JOURNAL_CONF)) as f:
        m = re.search(r"^SystemMaxUse=(\d+)M$", f.read(), re.M)
    bound = int(m.group(1)) << 20
    boots = subprocess.run(["journalctl", "-D", os.path.join(dump, "journal"), "--list-boots", "--no-pager", "-q"],
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True).stdout.strip().splitlines()
    results.update(journal_files=len(files), journal_mib=round(used / (1 << 20), 1), journal_boots=len(boots))
    fails.check(len(boots) >= 4 and 0 < used <= bound,
                f"the configuration partition's journal/: {len(boots)} boots (4 expected), {len(files)} files, "
                f"{used / (1 << 20):.1f} MiB <= SystemMaxUse {bound >> 20} MiB")
    os.remove(part)


def check_updates(a, work, proc, fails, env, key, img, sticks, cal_sha, results):
    """Steps 1-5 of the module's docstring, in one QEMU run."""
    journal = Journal(os.path.join(work, "serial.log"), proc)
    qmp = Qmp(os.path.join(work, "qmp.sock"))
    t0 = time.monotonic()
    line = booted(journal, "a", a.timeout, kiosk=False)
    results["boot_a_s"] = round(time.monotonic() - t0, 1)
    if not fails.check(line is not None, f"slot a boots ({results['boot_a_s']} s): {line}"):
        return
    # The first stick goes in as soon as slot a runs (its unit starts after the kiosk's).
    ok, secs = plug(qmp, journal, sticks["wrong"], 1, a.timeout)
    r = result_of(sticks["wrong"], env)
    fails.check(ok and r.get("outcome") == "refused" and "bad signature" in r.get("reason", ""),
                f"a bundle signed by another key: refused in {secs:.0f} s ({r.get('reason')})")
    fails.check(re.search(r"Started mogao-kiosk\.service", journal.text()) is not None, "slot a: the kiosk started")

    t0 = time.monotonic()
    ok, secs = plug(qmp, journal, sticks["good"], 2, a.install_timeout)
    r = result_of(sticks["good"], env)
    results["install_good_s"] = round(secs, 1)
    fails.check(ok and r.get("outcome") == "done" and "into slot b" in r.get("reason", ""),
                f"the good bundle: installed in {secs:.0f} s ({r.get('reason')})")
    line = booted(journal, "b", a.timeout)
    fails.check(line is not None and "update-test good" in line, f"the reboot runs slot b: {line}")
    m = journal.wait(r"boot assessment: mogao-kiosk is READY on slot b[^\r\n]*", 120)
    fails.check(m is not None, f"slot b: {m.group(0) if m else 'no boot assessment'}")
    m = journal.wait(r"systemd-bless-boot\[\d+\]: Marked boot as 'good'[^\r\n]*", 60)
    fails.check(m is not None, f"systemd-bless-boot marked slot b good: {m.group(0) if m else 'not seen'}")
    results["good_update_to_blessed_s"] = round(time.monotonic() - t0, 1)
    sha = config_file_sha(img, "etc/screen.mpcdi")
    fails.check(sha == cal_sha, f"after the good update the calibration is byte-identical (sha256 {sha})")

    t0 = time.monotonic()
    ok, secs = plug(qmp, journal, sticks["bad"], 3, a.install_timeout)
    r = result_of(sticks["bad"], env)
    results["install_bad_s"] = round(secs, 1)
    fails.check(ok and r.get("outcome") == "done" and "into slot a" in r.get("reason", ""),
                f"the bad bundle: installed in {secs:.0f} s ({r.get('reason')})")
    m = journal.wait(r"boot assessment FAILED: mogao-kiosk not READY on slot a[^\r\n]*", a.timeout)
    fails.check(m is not None, f"the bad root's boot assessment fails: {m.group(0) if m else 'not seen'}")
    line = booted(journal, "b", a.timeout)
    fails.check(line is not None and "update-test good" in line, f"rolled back: slot b runs again: {line}")
    m = journal.wait(r"slot a: the update '[^']*update-test bad[^']*' failed its boot assessment[^\r\n]*", 60)
    fails.check(m is not None, f"the journal names the rolled-back update: {m.group(0) if m else 'not seen'}")
    results["bad_update_to_rollback_s"] = round(time.monotonic() - t0, 1)
    check_previous_boot_log(a, qmp, journal, fails, env, sticks["logs"], results)


def main():
    set_name("update")
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--image", required=True)
    ap.add_argument("--repo", required=True)
    ap.add_argument("--kiosk", required=True, help="host mogao-kiosk (kiosk.toml, --check-config)")
    ap.add_argument("--farm", required=True, help="host mogao-farm (the test PKI)")
    ap.add_argument("--update-key", required=True, help="the private key whose public key the image trusts")
    ap.add_argument("--work", default="")
    ap.add_argument("--results", default="")
    ap.add_argument("--accel", default=os.environ.get("MOGAO_IMAGE_QEMU_ACCEL", "tcg"), choices=["tcg", "kvm"])
    ap.add_argument("--timeout", type=float, default=float(os.environ.get("MOGAO_UPDATE_TEST_TIMEOUT", "240")))
    ap.add_argument("--install-timeout", type=float, default=float(os.environ.get("MOGAO_UPDATE_INSTALL_TIMEOUT",
                                                                                  "300")))
    a = ap.parse_args()
    qemu = require_qemu(a.image)
    for t in ("mkfs.vfat", "mcopy", "mtype", "mdir", "openssl", "zstd", "debugfs", "e2fsck", "journalctl"):
        if shutil.which(t) is None:
            skip(f"{t} not found (apt-get install dosfstools mtools openssl zstd e2fsprogs)")
    if os.geteuid() != 0:
        skip("needs root (image/provision writes files owned by the kiosk user)")
    work = a.work or tempfile.mkdtemp(prefix="mogao-qemu-update-")
    os.makedirs(work, exist_ok=True)
    for name in ("serial.log", "qmp.sock"):
        if os.path.exists(os.path.join(work, name)):
            os.remove(os.path.join(work, name))
    env = dict(os.environ, MTOOLS_SKIP_CHECK="1")
    fails, results = Failures(), {}
    img, provision_cmd, key, cal_sha = provision(a, work, env)
    log("provisioned")
    again = subprocess.run(provision_cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    fails.check(again.returncode != 0 and "holds a configuration already" in again.stdout and "--wipe" in again.stdout,
                f"re-provisioning without --wipe is refused "
                f"({again.stdout.strip().splitlines()[-1][:160] if again.stdout else ''})")
    console_entry(img, env, work)
    good, bad, wrong = bundles(a, work)
    log("bundles made")
    results["bundle_mib"] = round(os.path.getsize(good) / (1 << 20), 1)
    serial = int(time.time())
    sticks = {"wrong": make_stick(a, work, "wrong", env, key, serial + 1, wrong),
              "good": make_stick(a, work, "good", env, key, serial + 2, good),
              "bad": make_stick(a, work, "bad", env, key, serial + 3, bad),
              "logs": make_request_stick(a, work, "logs", env, key, "logs", serial + 4)}
    results["prepare_s"] = round(time.monotonic() - T0, 1)
    cmd = qemu_command(qemu, a, work, img)
    log("starting QEMU: " + " ".join(cmd))
    with open(os.path.join(work, "qemu.log"), "w") as qemu_log:
        proc = subprocess.Popen(cmd, stdout=qemu_log, stderr=subprocess.STDOUT)
        try:
            check_updates(a, work, proc, fails, env, key, img, sticks, cal_sha, results)
        except Exception as e:  # noqa: BLE001 - report, then fail below
            fails.check(False, f"test aborted: {type(e).__name__}: {e}")
        finally:
            stop_qemu(proc)
    entries = esp_entries(img, env)
    fails.check("mogao-2-b.conf" in entries and any(re.match(r"mogao-3-a\+0-\d+\.conf$", e) for e in entries),
                f"on the ESP: slot b blessed, slot a with no tries left ({entries})")
    sha = config_file_sha(img, "etc/screen.mpcdi")
    fails.check(sha == cal_sha,
                f"after both updates the calibration is byte-identical (sha256 {sha}, provisioned {cal_sha})")
    journal_on_disk(a, img, work, fails, results)
    results["test_s"] = round(time.monotonic() - T0, 1)
    results["failures"] = fails.items
    log(f"figures: {results}")
    if a.results:
        with open(a.results, "w") as f:
            json.dump(results, f, indent=2)
    if fails.items:
        tail = "\n".join(Journal(os.path.join(work, "serial.log"), proc).text().splitlines()[-80:])
        log("serial console (last lines):\n" + tail)
        log(f"{len(fails.items)} check(s) failed; logs in {work}")
        return 1
    for big in [img, good, bad, *sticks.values()]:
        os.remove(big)
    log("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
