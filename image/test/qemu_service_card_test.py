#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Boots the appliance image in QEMU with its configuration partition wiped, and checks that the box
boots on to the kiosk's service card instead of emergency mode (appliance liveness).

    qemu_service_card_test.py --image mogao-kiosk.img --repo SRC [--work DIR] [--accel tcg|kvm]

A copy of the image gets its configuration partition (partition 3, label mogao-config) zeroed over
its first 4 MiB -- no filesystem, no label: what a missing, unprovisioned-and-damaged or corrupt
partition looks like to the boot -- and a test-only loader entry that runs image/test/selftest.sh in
its service-card mode from a second disk. The shipped image is never changed. QEMU as in
qemu_boot_test.py (q35, OVMF, virtio-gpu with 3 outputs, TCG).

Assertions (each printed; any failure fails the test):
  * mogao-kiosk.service becomes active (READY) although /etc/mogao is not mounted;
  * neither emergency.target nor rescue.target is active;
  * the kiosk's journal says "service card on every output: <reason>";
  * each of the 3 outputs is lit (screendump not black) in its mode;
  * 15 s later the kiosk is still active and has not restarted (it feeds the watchdog).
Exit 77 (skip) with a message when QEMU, OVMF, mtools or the image are missing.
"""
import argparse
import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import time

from qemu_common import IMAGE_ENTRY, T0, Failures, Serial, log, set_name, stop_qemu  # noqa: E402 (this folder)
from qemu_boot_test import (MODES, OUTPUTS, OVMF_CODE, OVMF_VARS, Qmp, install_selftest_entry,  # noqa: E402
                            ppm_stats, require_qemu, run)

WIPE_MIB = 4  # the ext4 superblock is at 1 KiB; 4 MiB also clears the group descriptors


def partition(image, n):
    """(start sector, sectors) of partition n, as image/lib/common.sh's img_partition reads it."""
    for line in run(["sfdisk", "--dump", image]).stdout.splitlines():
        if re.match(rf"^\S*{n} :", line):
            start = int(re.search(r"start= *(\d+)", line).group(1))
            size = int(re.search(r"size= *(\d+)", line).group(1))
            return start, size
    raise RuntimeError(f"{image} has no partition {n}")


def prepare(a, work, env):
    """The test copy (config partition wiped, self-test loader entry) and the test disk."""
    img = os.path.join(work, "service-card.img")
    log(f"copying {a.image}")
    run(["cp", "--sparse=always", a.image, img])
    dump = run(["sfdisk", "--dump", img]).stdout
    if 'name="mogao-config"' not in dump:
        raise RuntimeError(f"{a.image} has no mogao-config partition")
    start, size = partition(img, 3)
    run(["dd", "if=/dev/zero", f"of={img}", "bs=512", f"seek={start}", f"count={min(size, WIPE_MIB * 2048)}",
         "conv=notrunc", "status=none"])
    log(f"configuration partition (sector {start}, {size} sectors): first {WIPE_MIB} MiB zeroed")
    esp = f"{img}@@1M"
    entry = run(["mtype", "-i", esp, IMAGE_ENTRY], env=env).stdout
    options = re.search(r"^options (.*)$", entry, re.M).group(1)
    options = re.sub(r"\b(quiet|loglevel=\d|systemd.show_status=\S+)\b", "", options)
    boot = "udevadm settle; mount -o ro /dev/disk/by-label/mogao-test /mnt && exec /bin/sh /mnt/selftest.sh"
    extra = ["console=tty0", "console=ttyS0,115200", "systemd.show_status=true",
             "systemd.journald.forward_to_console=1",
             *[f"video=Virtual-{i + 1}:{MODES[i][0]}x{MODES[i][1]}e" for i in range(1, OUTPUTS)],
             "systemd.unit=multi-user.target", "systemd.wants=kernel-command-line.service",
             f"systemd.run=\"/bin/sh -c '{boot}'\"", "systemd.run_success_action=none",
             "systemd.run_failure_action=none", "mogao.selftest.mode=service-card"]
    install_selftest_entry(work, esp, "mogao self-test, service card (QEMU)", options, extra, env)
    disk = os.path.join(work, "testdisk")
    shutil.rmtree(disk, ignore_errors=True)
    os.makedirs(disk)
    shutil.copy(os.path.join(a.repo, "image", "test", "selftest.sh"), os.path.join(disk, "selftest.sh"))
    testimg = os.path.join(work, "testdisk.img")
    if os.path.exists(testimg):
        os.remove(testimg)
    run(["truncate", "-s", "16M", testimg])
    run(["mke2fs", "-q", "-F", "-t", "ext4", "-L", "mogao-test", "-d", disk, testimg])
    return img, testimg


def qemu_command(qemu, a, work, img, testimg):
    vars_fd = os.path.join(work, "OVMF_VARS.fd")
    shutil.copy(OVMF_VARS, vars_fd)
    return [qemu, "-nodefaults", "-machine", "q35", "-m", "2048", "-smp", "2",
            "-accel", "kvm" if a.accel == "kvm" else "tcg", "-cpu", "host" if a.accel == "kvm" else "max",
            "-drive", f"if=pflash,format=raw,readonly=on,file={OVMF_CODE}",
            "-drive", f"if=pflash,format=raw,file={vars_fd}",
            "-drive", f"if=virtio,format=raw,file={img}",
            "-drive", f"if=virtio,format=raw,readonly=on,file={testimg}",
            "-device", f"virtio-gpu-pci,id=gpu0,max_outputs={OUTPUTS},xres={MODES[0][0]},yres={MODES[0][1]},edid=off",
            "-netdev", "user,id=n0,ipv4=off,ipv6=on", "-device", "virtio-net-pci,netdev=n0",
            "-display", "none", "-serial", f"file:{os.path.join(work, 'serial.log')}",
            "-serial", f"unix:{os.path.join(work, 'ctl.sock')},server=on,wait=off",
            "-qmp", f"unix:{os.path.join(work, 'qmp.sock')},server=on,wait=off"]


def check_guest(a, work, proc, fails):
    serial = Serial(os.path.join(work, "serial.log"))
    alive = lambda: proc.poll() is None  # noqa: E731
    qmp = Qmp(os.path.join(work, "qmp.sock"))
    ctl = socket.socket(socket.AF_UNIX)
    ctl.connect(os.path.join(work, "ctl.sock"))
    t, _ = serial.wait(r"start ", a.timeout, alive)
    if not fails.check(t is not None, "the self-test started in the guest (serial marker)"):
        return serial
    t, text = serial.wait(r"service-card-shown", a.timeout, alive)
    if fails.check(t is not None, f"the guest reached the service-card checks ({text})"):
        time.sleep(5)  # the first flips are done
        for head in range(OUTPUTS):
            path = os.path.join(work, f"service-card-head{head}.ppm")
            qmp.cmd("screendump", filename=path, device="gpu0", head=head)
            w, h, mean, dark = ppm_stats(path)
            fails.check((w, h) == MODES[head] and mean > 10 and dark < 0.5,
                        f"output {head} lit by the service card in mode {w}x{h} (expected "
                        f"{MODES[head][0]}x{MODES[head][1]}): mean code {mean:.1f}, dark fraction {dark:.2f}")
    ctl.sendall(b"shots-done\n")
    t, text = serial.wait(r"service-card-steady", 120, alive)
    fails.check(text is not None and "state=active" in text and "restarts=0" in text,
                f"the kiosk stayed up on the service card without a restart ({text})")
    t, _ = serial.wait(r"done ", 120, alive)
    fails.check(t is not None, "the self-test finished")
    for _, mark in serial.marks:
        if mark.startswith("FAIL "):
            fails.check(False, f"guest: {mark[5:]}")
        elif mark.startswith("ok "):
            fails.check(True, f"guest: {mark[3:]}")
    return serial


def main():
    set_name("service-card")
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--image", required=True)
    ap.add_argument("--repo", required=True)
    ap.add_argument("--work", default="")
    ap.add_argument("--accel", default=os.environ.get("MOGAO_IMAGE_QEMU_ACCEL", "tcg"), choices=["tcg", "kvm"])
    ap.add_argument("--timeout", type=float, default=float(os.environ.get("MOGAO_IMAGE_BOOT_TIMEOUT", "900")))
    a = ap.parse_args()
    qemu = require_qemu(a.image)
    work = a.work or tempfile.mkdtemp(prefix="mogao-qemu-card-")
    os.makedirs(work, exist_ok=True)
    for name in ("serial.log", "qmp.sock", "ctl.sock"):
        if os.path.exists(os.path.join(work, name)):
            os.remove(os.path.join(work, name))
    env = dict(os.environ, MTOOLS_SKIP_CHECK="1")
    fails = Failures()
    img, testimg = prepare(a, work, env)
    cmd = qemu_command(qemu, a, work, img, testimg)
    log("starting QEMU: " + " ".join(cmd))
    with open(os.path.join(work, "qemu.log"), "w") as qemu_log:
        proc = subprocess.Popen(cmd, stdout=qemu_log, stderr=subprocess.STDOUT)
        serial = None
        try:
            serial = check_guest(a, work, proc, fails)
        except Exception as e:  # noqa: BLE001 - report, then fail below
            fails.check(False, f"test aborted: {type(e).__name__}: {e}")
        finally:
            stop_qemu(proc)
    log(f"test seconds: {time.monotonic() - T0:.1f}")
    if fails.items:
        if serial is not None:
            log("serial console (last lines):\n" + serial.tail(80))
        log(f"{len(fails.items)} check(s) failed; logs in {work}")
        return 1
    for big in (img, testimg):
        if os.path.exists(big):
            os.remove(big)
    log("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
