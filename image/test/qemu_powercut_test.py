#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Cuts the power of the appliance in QEMU while it writes its calibration or configuration, and
checks that every file it comes up on is byte-identical to the old or to the new version.

    qemu_powercut_test.py --image mogao-kiosk.img --repo SRC --calibrate BIN --rig-film BIN
                          --kiosk BIN --farm BIN [--binaries-into-image] [--cuts N] [--seed S]
                          [--reboot-every N] [--work DIR] [--results FILE]
                          [--write-docs docs/reliability.md]

The writes under test are the appliance's own programs from the image, on its configuration
partition (ext4 with a journal, mounted as its fstab says):
  * calibrate: `mogao-calibrate --install /var/lib/mogao/etc/screen.mpcdi` from captured images
    (the virtual rig rigs/qemu.toml films the patterns on the host, --scale 0.5): over an installed
    calibration (OLD, the same captures with --fit-screen), it keeps the old files as *.last-good
    and writes the new MPCDI and its models file, in --out and in the install path;
  * config: the kiosk's start on a changed kiosk.toml and MPCDI (mogao-kiosk with
    MOGAO_LAST_GOOD_DIR, as its unit runs it), which replaces its last good copies of both
    (kiosk/config/last_loaded.h), the copies it falls back on when a file is bad at the next start.

How: the image's kernel and initramfs are booted directly with init=/powercut-init
(image/test/powercut_guest.sh, written onto the test copy's root) instead of systemd, so that a
boot costs seconds under TCG. The first boot is saved (savevm into QEMU's -snapshot overlay);
from it each scenario runs once up to the start of its write phase (mogao-calibrate: frozen with
SIGSTOP as its first file in --out appears; the kiosk: before it starts) and that point is saved
too. A reference run goes on from there without a cut and defines NEW (its files, read as below)
and the write window. Then, per cut: back to the saved point (loadvm), "go", a
random delay (seeded; uniform over 1.5 x the time from "go" to the reference's last change of the
watched folder), QMP stop: guest RAM and the page cache are lost. The disk as it is then is copied
out (blockdev-backup) and its configuration partition read as a boot would (e2fsck -p replays the
journal, debugfs copies the files); every --reboot-every-th cut also boots the guest on that disk,
whose own report (fsck, mount, sha256 of every file) must agree. QEMU's disk has no volatile
cache: writes the guest submitted before the cut are kept (a drive that honours flushes).

Verdict per cut: every calibration or configuration file (*.mpcdi, *.models.json, *.last-good,
*.last-loaded) equals its OLD or its NEW bytes (missing only where OLD was missing); the MPCDI and
its models file come from the same version. Stage of the cut: "before" (the scenario's files all
OLD, no temporary), "during" (some written or a temporary left), "after" (all NEW).
Exit 0 when no cut leaves a missing, torn or mixed file; 1 otherwise; 77 (skip) when QEMU, mtools,
debugfs or the image are missing.
"""
import argparse
import hashlib
import io
import json
import os
import random
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import zipfile

from qemu_common import IMAGE_ENTRY, IMAGE_KERNEL, T0, Failures, Serial, log, set_name, stop_qemu  # noqa: E402,E501
from qemu_boot_test import Qmp, run  # noqa: E402
import powercut_report  # noqa: E402

SKIP = 77
SCALE = 0.5            # rigs/qemu.toml at half resolution (a 0.5 MB MPCDI); --no-bow: a calibration in
                       # about a minute under TCG (the guest runs it once; each cut resumes its write phase)
RIG = "rigs/qemu.toml"
ROOT_PART, CONFIG_PART = 2, 3
SCENARIOS = ("calibrate", "config")
VERDICT = re.compile(r"(\.mpcdi|\.models\.json|\.last-good|\.last-loaded)$")
# The scenario's own files: what its stage is judged on.
SUBJECT = {"calibrate": re.compile(r"^etc/screen\."), "config": re.compile(r"^last-good/")}
FOLDERS = ("etc", "calibration", "last-good")  # on the configuration partition; as powercut_guest.sh reports
MARGIN = 1.5           # cut delays: uniform over [0, MARGIN x the reference's last write after "go"]


def skip(msg):
    print(f"SKIP: {msg}", flush=True)
    sys.exit(SKIP)


def partition(image, n):
    """(start sector, sectors) of partition n."""
    for line in run(["sfdisk", "--dump", image]).stdout.splitlines():
        if re.match(rf"^\S*{n} :", line):
            return (int(re.search(r"start= *(\d+)", line).group(1)), int(re.search(r"size= *(\d+)", line).group(1)))
    raise RuntimeError(f"{image} has no partition {n}")


def debugfs_write(img, part, commands):
    """Runs debugfs -w requests on partition `part` of the raw image (one per line)."""
    start, _ = partition(img, part)
    r = subprocess.run(["debugfs", "-w", "-f", "-", f"{img}?offset={start * 512}"], input="\n".join(commands) + "\n",
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, check=True)
    bad = [ln for ln in r.stdout.splitlines() if re.search(r"(error|not found|cannot|Could not)", ln, re.I)]
    if bad:
        raise RuntimeError("debugfs: " + "; ".join(bad))


def host_calibration(a, captures, out, extra):
    run([a.calibrate, "--site", os.path.join(a.repo, RIG), "--images", captures, "--scale", str(SCALE),
         "--camera-transfer", "linear", "--no-bow", "--out", out, *extra])
    return os.path.join(out, "calibration.mpcdi"), os.path.join(out, "calibration.models.json")


def kiosk_toml(a, rate_hz):
    """The kiosk's configuration: headless outputs (the guest has no GPU), the installed MPCDI."""
    overrides = ['farm.endpoint="[fec0::2]:48615"', 'farm.ca="pki/ca.pem"', 'farm.cert="pki/appliance-museum-1.pem"',
                 'farm.key="pki/appliance-museum-1.key"', f"display.rate_hz={rate_hz}", 'outputs.backend="headless"',
                 'calibration.source="screen.mpcdi"', 'quality.content="480x270"', "stats.file="]
    printed = subprocess.run([a.kiosk, "--print-config", *overrides], check=True, stdout=subprocess.PIPE, text=True)
    return "# written by image/test/qemu_powercut_test.py\n" + printed.stdout


def prepare_config(a, work, img, old_cal, new_cal):
    """The configuration partition before the writes: OLD calibration installed; kiosk.toml and
    the MPCDI changed since the kiosk's last good copies were made (those hold older bytes)."""
    pki = os.path.join(work, "pki")
    shutil.rmtree(pki, ignore_errors=True)
    run([a.farm, "pki", "init-ca", "--dir", pki])
    run([a.farm, "pki", "issue-appliance", "--dir", pki, "--name", "museum-1"])
    files = os.path.join(work, "config-files")
    shutil.rmtree(files, ignore_errors=True)
    os.makedirs(files)
    for name, rate in (("kiosk.toml", 1), ("kiosk-before.toml", 2)):
        with open(os.path.join(files, name), "w") as f:
            f.write(kiosk_toml(a, rate))
    check = os.path.join(files, "check")
    os.makedirs(os.path.join(check, "pki"))
    for f in ("ca.pem", "appliance-museum-1.pem", "appliance-museum-1.key"):
        shutil.copy(os.path.join(pki, f), os.path.join(check, "pki", f))
    shutil.copy(os.path.join(files, "kiosk.toml"), os.path.join(check, "kiosk.toml"))
    shutil.copy(old_cal[0], os.path.join(check, "screen.mpcdi"))
    run([a.kiosk, "--config", os.path.join(check, "kiosk.toml"), "--check-config"])
    last = "%etc%mogao%"
    cmds = [f"write {old_cal[0]} etc/screen.mpcdi", f"write {old_cal[1]} etc/screen.models.json",
            f"write {files}/kiosk.toml etc/kiosk.toml", "mkdir etc/pki", "mkdir last-good",
            f"write {files}/kiosk-before.toml last-good/{last}kiosk.toml.last-loaded",
            f"write {new_cal[0]} last-good/{last}screen.mpcdi.last-loaded"]
    cmds += [f"write {pki}/{f} etc/pki/{f}" for f in ("ca.pem", "appliance-museum-1.pem", "appliance-museum-1.key")]
    debugfs_write(img, CONFIG_PART, cmds)


def prepare(a, work, env):
    """The test copy (init script on its root, the configuration partition filled), its kernel,
    initramfs and command line, the test disk (captures, site file) and the qcow2 overlay."""
    img = os.path.join(work, "powercut.img")
    run(["cp", "--sparse=always", a.image, img])
    for f in ("vmlinuz", "initrd.img"):
        run(["mcopy", "-o", "-i", f"{img}@@1M", f"::{os.path.dirname(IMAGE_KERNEL)}/{f}", os.path.join(work, f)],
            env=env)
    entry = run(["mtype", "-i", f"{img}@@1M", IMAGE_ENTRY], env=env).stdout
    options = re.search(r"^options (.*)$", entry, re.M).group(1)
    keep = [o for o in options.split() if o.split("=")[0] in ("root", "ro", "rootfstype")]
    cmdline = " ".join(keep + ["init=/powercut-init", "console=ttyS0,115200", "loglevel=3", "panic=0"])
    root = [f"write {os.path.join(a.repo, 'image/test/powercut_guest.sh')} powercut-init",
            "sif powercut-init mode 0100755"]
    if a.binaries_into_image:  # this build's programs instead of the image's (an image built earlier)
        for tool, name in ((a.calibrate, "mogao-calibrate"), (a.kiosk, "mogao-kiosk")):
            stripped = os.path.join(work, name)
            run(["strip", "-o", stripped, tool])
            root += [f"rm usr/bin/{name}", f"write {stripped} usr/bin/{name}", f"sif usr/bin/{name} mode 0100755"]
    debugfs_write(img, ROOT_PART, root)
    disk = os.path.join(work, "testdisk")
    shutil.rmtree(disk, ignore_errors=True)
    captures = os.path.join(disk, "captures")
    site = os.path.join(a.repo, RIG)
    run([a.calibrate, "patterns", "--site", site, "--scale", str(SCALE), "--out", captures])
    run([a.rig_film, "--rig", site, "--scale", str(SCALE), "film", "--patterns", captures])
    shutil.copy(site, os.path.join(disk, "site.toml"))
    with open(os.path.join(disk, "scale"), "w") as f:
        f.write(f"{SCALE}\n")
    old_cal = host_calibration(a, captures, os.path.join(work, "old-calibration"), ["--fit-screen"])
    new_cal = host_calibration(a, captures, os.path.join(work, "host-calibration"), [])
    prepare_config(a, work, img, old_cal, new_cal)
    testimg = os.path.join(work, "testdisk.img")
    if os.path.exists(testimg):
        os.remove(testimg)
    run(["truncate", "-s", "64M", testimg])
    run(["mke2fs", "-q", "-F", "-t", "ext4", "-L", "mogao-test", "-d", disk, testimg])
    return img, testimg, cmdline


def qemu_command(work, img, testimg, cmdline):
    """-snapshot: QEMU's own temporary qcow2 overlay over the copy holds the writes and the saved
    states (savevm/loadvm), so no qemu-img is needed and the copy stays as prepared."""
    return ["qemu-system-x86_64", "-nodefaults", "-snapshot", "-machine", "q35", "-m", "1024", "-smp", "2",
            "-accel", "tcg", "-cpu", "max", "-kernel", os.path.join(work, "vmlinuz"),
            "-initrd", os.path.join(work, "initrd.img"), "-append", cmdline,
            "-drive", f"if=virtio,format=raw,file={img}",
            "-drive", f"if=virtio,format=raw,readonly=on,file={testimg}",
            "-display", "none", "-serial", f"file:{os.path.join(work, 'serial.log')}",
            "-serial", f"unix:{os.path.join(work, 'ctl.sock')},server=on,wait=off",
            "-qmp", f"unix:{os.path.join(work, 'qmp.sock')},server=on,wait=off"]


class Guest:
    """The running QEMU: serial markers read from a cursor on, the control port, QMP and HMP."""

    def __init__(self, work, proc):
        self.serial = Serial(os.path.join(work, "serial.log"))
        self.proc = proc
        self.qmp = Qmp(os.path.join(work, "qmp.sock"))
        self.ctl = socket.socket(socket.AF_UNIX)
        self.ctl.connect(os.path.join(work, "ctl.sock"))
        self.cursor = 0

    def wait(self, pattern, timeout):
        """The next marker from the cursor on matching `pattern`; moves the cursor past it."""
        rx = re.compile(pattern)
        deadline = time.monotonic() + timeout
        while True:
            self.serial.pump()
            for i in range(self.cursor, len(self.serial.marks)):
                if rx.match(self.serial.marks[i][1]):
                    self.cursor = i + 1
                    return self.serial.marks[i][1]
            if time.monotonic() > deadline or self.proc.poll() is not None:
                raise TimeoutError(f"no guest marker '{pattern}' within {timeout:.0f} s")
            time.sleep(0.05)

    def skip_to_end(self):
        self.serial.pump()
        self.cursor = len(self.serial.marks)

    def send(self, line):
        self.ctl.sendall(line.encode() + b"\n")

    def hmp(self, line):
        out = self.qmp.cmd("human-monitor-command", **{"command-line": line})
        if out and out.strip():
            raise RuntimeError(f"HMP '{line}': {out.strip()}")

    def cut(self, work, part):
        """The power cut: the VM stopped where it is; what its disk holds then (the requests the
        guest submitted are completed by the stop's drain) is copied out and its configuration
        partition read as the next boot would. Returns read_partition's result."""
        self.qmp.cmd("stop")
        target = os.path.join(work, "cut.img")
        if os.path.exists(target):
            os.remove(target)
        # The whole disk into a file of ours (drive-backup would create its target with the
        # source's flags: under -snapshot a temporary file, deleted when the copy ends; a node over a
        # slice of the disk may not share the device's write permission).
        size = next(b["inserted"]["image"]["virtual-size"] for b in self.qmp.cmd("query-block")
                    if b["device"] == "virtio0")
        with open(target, "wb") as f:
            f.truncate(size)
        self.qmp.cmd("blockdev-add", driver="raw", file={"driver": "file", "filename": target},
                     **{"node-name": "powercut-copy"})
        try:
            self.qmp.cmd("blockdev-backup", device="virtio0", target="powercut-copy", sync="full",
                         **{"job-id": "powercut-copy"})
            deadline = time.monotonic() + 300
            while not any(e.get("event") == "BLOCK_JOB_COMPLETED" for e in self.qmp.events):
                if time.monotonic() > deadline:
                    raise TimeoutError("the copy of the disk did not complete")
                self.qmp.poll_events(0.2)
            done = [e for e in self.qmp.events if e.get("event") == "BLOCK_JOB_COMPLETED"][0]
            self.qmp.events.clear()
            if done["data"].get("error"):
                raise RuntimeError(f"blockdev-backup: {done['data']['error']}")
        finally:
            self.qmp.cmd("blockdev-del", **{"node-name": "powercut-copy"})
        part_file = os.path.join(work, "cut-config.img")  # e2fsck cannot re-open an ?offset= device
        copy_slice(target, part_file, part[0] * 512, part[1] * 512)
        return read_partition(part_file, os.path.join(work, "config-dump"))

    def state(self, timeout):
        """Waits for the next boot's report: {path: (sha256, bytes)}, [temporaries]."""
        self.wait(r"boot ", timeout)
        files, temps = {}, []
        rx = re.compile(r"(file|temp|state-done) ?(.*)")
        while True:
            kind, rest = rx.match(self.wait(r"(file|temp|state-done)", timeout)).groups()
            if kind == "state-done":
                return files, temps
            parts = rest.split()
            if kind == "temp" or parts[0].endswith((".tmp", ".staged")):
                temps.append(parts[0])
            else:
                files[parts[0]] = (parts[1], int(parts[2]))


def copy_slice(src, dst, offset, size, chunk=1 << 20):
    """Bytes [offset, offset + size) of src into a sparse file dst."""
    with open(src, "rb") as fin, open(dst, "wb") as fout:
        fin.seek(offset)
        left = size
        while left > 0:
            data = fin.read(min(chunk, left))
            if not data:
                break
            if data.count(0) == len(data):
                fout.seek(len(data), os.SEEK_CUR)
            else:
                fout.write(data)
            left -= len(data)
        fout.truncate(size)


def read_partition(part, dump):
    """The files a boot would find on a copy of the configuration partition: e2fsck -p replays the
    journal as the appliance's systemd-fsck does, then debugfs copies the folders out. Returns
    {path: identity}, {path: (sha256, bytes)}, [temporaries], e2fsck's exit status."""
    fsck = subprocess.run(["e2fsck", "-p", part], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    shutil.rmtree(dump, ignore_errors=True)
    os.makedirs(dump)
    run(["debugfs", "-R", f"rdump {' '.join('/' + d for d in FOLDERS)} {dump}", part])
    files, raw, temps = {}, {}, []
    for d in FOLDERS:
        if not os.path.isdir(os.path.join(dump, d)):
            continue
        for name in sorted(os.listdir(os.path.join(dump, d))):
            full = os.path.join(dump, d, name)
            if not os.path.isfile(full):
                continue
            if name.startswith(".") or name.endswith(".tmp") or name.endswith(".staged"):
                temps.append(f"{d}/{name}")
            else:
                with open(full, "rb") as f:
                    data = f.read()
                raw[f"{d}/{name}"] = (hashlib.sha256(data).hexdigest(), len(data))
                files[f"{d}/{name}"] = identity(name, data)
    return files, raw, temps, fsck.returncode


def identity(name, data):
    """What "the same version" compares: the bytes; for an MPCDI its entries with mpcdi.xml's date
    attribute blanked (the writer stamps the second it ran: a cut run writes the reference's
    calibration one second later). A torn archive has no entries: its bytes, equal to nothing."""
    if name.endswith(".mpcdi"):
        try:
            with zipfile.ZipFile(io.BytesIO(data)) as z:
                h = hashlib.sha256()
                for entry in sorted(z.namelist()):
                    body = z.read(entry)
                    if entry == "mpcdi.xml":
                        body = re.sub(rb'date="[^"]*"', b'date=""', body, count=1)
                    h.update(entry.encode() + b"\0" + hashlib.sha256(body).digest())
                return "mpcdi entries " + h.hexdigest()
        except (zipfile.BadZipFile, OSError, EOFError, ValueError):
            pass
    return hashlib.sha256(data).hexdigest()


def classify(scenario, old, new, cut_files, temps):
    """(stage, problems) of one cut: see the module's docstring."""
    problems = []
    for path in sorted(set(old) | set(new) | set(cut_files)):
        if not VERDICT.search(path):
            continue
        got = cut_files.get(path, "missing")
        if got not in (old.get(path, "missing"), new.get(path, "missing")):
            what = "missing" if got == "missing" else "torn (matches neither version)"
            problems.append(f"{path}: {what}")
    version = {}
    for path in ("etc/screen.mpcdi", "etc/screen.models.json"):
        got = cut_files.get(path, "missing")
        version[path] = "new" if got == new.get(path) else "old" if got == old.get(path) else "?"
    if scenario == "calibrate" and len(set(version.values())) > 1:
        problems.append("mixed: " + ", ".join(f"{p} {v}" for p, v in version.items()))
    mine = [p for p in set(old) | set(new) | set(cut_files) if SUBJECT[scenario].match(p) and VERDICT.search(p)]
    changed = [p for p in mine if cut_files.get(p, "missing") != old.get(p, "missing")]
    still_old = [p for p in mine if old.get(p, "missing") != new.get(p, "missing")
                 and cut_files.get(p, "missing") == old.get(p, "missing")]
    stage = "after" if not still_old else "during" if changed or temps else "before"
    return stage, problems


def restore(g, name):
    """Back to a saved point (loadvm keeps a stopped VM stopped), running, cursor at the end."""
    g.hmp(f"loadvm {name}")
    g.qmp.cmd("cont")
    g.skip_to_end()


def reference_run(g, scenario, work, part, timeout):
    """From the freeze point to the end without a cut: NEW, and the write window's end, the last
    change of the watched folder after "go" (guest clock, seconds). Resumed by loadvm as every cut
    is (the first seconds after a loadvm run slower under TCG)."""
    restore(g, scenario)
    start = g.cursor
    g.send("go")
    done = g.wait(r"exit ", timeout)
    g.wait(r"ready", 120)
    marks = [m for _, m in g.serial.marks[start:g.cursor]]
    go = next(float(m.split()[1]) for m in marks if m.startswith("go "))
    events = [m for m in marks if m.startswith("ev ")]
    window = max([float(m.split()[1]) - go for m in events] + [0.0])
    new, _, temps, fsck = g.cut(work, part)
    return window, float(done.split()[2]) - go, done.split()[1], events, new, temps, fsck


def one_cut(g, scenario, old, new, delay, reboot, work, part, timeout):
    restore(g, scenario)
    g.send("go")
    time.sleep(delay)
    files, raw, temps, fsck = g.cut(work, part)
    g.serial.pump()
    seen = [m for _, m in g.serial.marks[g.cursor:] if m.startswith("ev ")]
    stage, problems = classify(scenario, old, new, files, temps)
    if fsck & ~1:
        problems.append(f"e2fsck -p exit {fsck}")
    cut = {"delay_s": round(delay, 3), "stage": stage, "problems": problems, "temporaries": temps,
           "last_event": seen[-1] if seen else "", "rebooted": reboot}
    if reboot:  # the same disk state booted: the guest must find what the copy showed
        g.qmp.cmd("system_reset")
        g.qmp.cmd("cont")
        guest_files, guest_temps = g.state(timeout)
        if guest_files != raw or sorted(guest_temps) != sorted(temps):
            problems.append(f"the rebooted guest found other files than the copy: {guest_files} {guest_temps}")
    return cut


def run_scenario(g, scenario, a, rng, work, part):
    """Freeze point, reference run, cuts; returns the scenario's results."""
    restore(g, "booted")
    g.send(scenario)
    g.wait(r"frozen", a.timeout)
    g.hmp(f"savevm {scenario}")
    log(f"{scenario}: frozen at the start of its write phase, saved")
    old = g.base
    length, run_s, rc, events, new, temps, fsck = reference_run(g, scenario, work, part, a.timeout)
    changed = sorted(p for p in set(new) | set(old) if new.get(p) != old.get(p))
    log(f"{scenario}: reference run {rc}, last write {length:.2f} s after go, exit {run_s:.2f} s; "
        f"changed {changed}; "
        f"temporaries {temps}; e2fsck {fsck}")
    res = {"reference_seconds": round(length, 3), "reference_exit_seconds": round(run_s, 3), "reference_rc": rc,
           "reference_events": events[-20:],
           "changed": changed, "cuts": []}
    if rc != "rc=0" or not changed or temps:
        res["error"] = f"the reference run did not write cleanly (exit {rc}; changed {changed}; temporaries {temps})"
        return res
    for i in range(a.cuts):
        delay = rng.uniform(0.0, MARGIN * length)
        cut = one_cut(g, scenario, old, new, delay, a.reboot_every > 0 and i % a.reboot_every == 0, work, part,
                      a.timeout)
        res["cuts"].append(cut)
        log(f"{scenario} cut {i + 1}/{a.cuts}: {delay:.3f} s after go -> {cut['stage']}"
            + (" (rebooted)" if cut["rebooted"] else "") + f"; last event seen: {cut['last_event'][:100]}"
            + (f"; PROBLEMS: {cut['problems']}" if cut["problems"] else "")
            + (f"; temporaries left: {cut['temporaries']}" if cut["temporaries"] else ""))
    return res


def drive(a, work, proc, rng, fails, part):
    g = Guest(work, proc)
    t = time.monotonic()
    guest_files, _ = g.state(a.timeout)
    g.wait(r"ready", 120)
    log(f"first boot: {time.monotonic() - t:.1f} s, {len(guest_files)} files")
    g.base, raw, temps, fsck = g.cut(work, part)  # OLD, read as every cut is
    fails.check(raw == guest_files and not temps and fsck & ~1 == 0,
                f"the copy of the first boot's disk holds what the guest reported ({len(raw)} files)")
    g.qmp.cmd("cont")
    g.hmp("savevm booted")
    results = {}
    for scenario in a.scenarios:
        t = time.monotonic()
        res = run_scenario(g, scenario, a, rng, work, part)
        res["seconds"] = round(time.monotonic() - t, 1)
        results[scenario] = res
        fails.check("error" not in res, f"{scenario}: reference run wrote its files ({res.get('error', 'ok')})")
        bad = [c for c in res["cuts"] if c["problems"]]
        stages = {s: sum(c["stage"] == s for c in res["cuts"]) for s in ("before", "during", "after")}
        fails.check(not bad, f"{scenario}: {len(res['cuts'])} cuts ({stages}), {len(bad)} left a missing, torn or "
                    "mixed file")
    return results


def main():
    set_name("powercut")
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--image", required=True)
    ap.add_argument("--repo", required=True)
    for tool in ("calibrate", "rig-film", "kiosk", "farm"):
        ap.add_argument(f"--{tool}", required=True, help=f"host mogao-{tool} (prepares the files)")
    ap.add_argument("--cuts", type=int, default=int(os.environ.get("MOGAO_POWERCUT_CUTS", "20")),
                    help="cuts per scenario")
    ap.add_argument("--binaries-into-image", action="store_true",
                    help="test --calibrate and --kiosk (stripped, written over the copy's /usr/bin ones)")
    ap.add_argument("--reboot-every", type=int, default=10,
                    help="every N-th cut also boots the guest on the cut disk (0: none)")
    ap.add_argument("--scenarios", default=",".join(SCENARIOS))
    ap.add_argument("--seed", type=int, default=int(os.environ.get("MOGAO_POWERCUT_SEED", "1")))
    ap.add_argument("--work", default="")
    ap.add_argument("--results", default="")
    ap.add_argument("--write-docs", default="", help="regenerate the power-cut table in this markdown file")
    ap.add_argument("--timeout", type=float, default=900.0, help="per guest step, s")
    a = ap.parse_args()
    a.scenarios = [s for s in a.scenarios.split(",") if s]
    for tool in ("qemu-system-x86_64", "mcopy", "mtype", "debugfs", "mke2fs", "sfdisk"):
        if shutil.which(tool) is None:
            skip(f"{tool} not found")
    if not os.path.exists(a.image):
        skip(f"no image at {a.image}")
    work = a.work or tempfile.mkdtemp(prefix="mogao-qemu-powercut-")
    os.makedirs(work, exist_ok=True)
    for name in ("serial.log", "qmp.sock", "ctl.sock"):
        if os.path.exists(os.path.join(work, name)):
            os.remove(os.path.join(work, name))
    env = dict(os.environ, MTOOLS_SKIP_CHECK="1")
    fails = Failures()
    log(f"seed {a.seed}, {a.cuts} cuts per scenario ({', '.join(a.scenarios)})")
    img, testimg, cmdline = prepare(a, work, env)
    cmd = qemu_command(work, img, testimg, cmdline)
    log("starting QEMU: " + " ".join(cmd))
    rng = random.Random(a.seed)
    results = {"seed": a.seed, "cuts_per_scenario": a.cuts, "scale": SCALE}
    with open(os.path.join(work, "qemu.log"), "w") as qemu_log:
        proc = subprocess.Popen(cmd, stdout=qemu_log, stderr=subprocess.STDOUT)
        try:
            results["scenarios"] = drive(a, work, proc, rng, fails, partition(img, CONFIG_PART))
        except Exception as e:  # noqa: BLE001 - report, then fail below
            fails.check(False, f"test aborted: {type(e).__name__}: {e}")
        finally:
            stop_qemu(proc)
    results["seconds"] = round(time.monotonic() - T0, 1)
    results["failures"] = fails.items
    log(f"test seconds: {results['seconds']}")
    if a.results:
        with open(a.results, "w") as f:
            json.dump(results, f, indent=1)
    if a.write_docs and "scenarios" in results:
        powercut_report.write_docs(a.write_docs, results, " ".join(sys.argv))
    if fails.items:
        log("serial console (last lines):\n" + Serial(os.path.join(work, "serial.log")).tail(40))
        log(f"{len(fails.items)} check(s) failed; logs in {work}")
        return 1
    for big in (img, testimg, os.path.join(work, "cut.img"), os.path.join(work, "cut-config.img")):
        if os.path.exists(big):
            os.remove(big)
    log("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
