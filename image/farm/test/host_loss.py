# SPDX-License-Identifier: Apache-2.0
"""The host-loss phase of farm_qemu_test.py (--host-loss): a render host lost while the appliance is
served, twice, and its return.

  1. farm-render2's link cut (its tap down on the bridge), later restored;
  2. farm-render2's VM killed (SIGKILL to QEMU: a power cut), later booted again from its disk.

For each loss: seconds from the loss to the first frame on the wall that the appliance requested
after it (the host's headless kiosk, running throughout; its per-frame statistics) and to the
admin's journal line serving with 1 render rank; for each return: seconds from the return (link up;
the rebooted host's sshd active) to the admin serving with 2 render ranks again (rank 2 back on
farm-render2). The admin's journal lines reach the host as "follow ..." markers (selftest.sh), timed
on the host's clock when they arrive on the serial console.
"""
import json
import os
import re
import signal
import subprocess
import time

import farmvm

NEW_FRAME_GOAL_S = 10.0
BACK_GOAL_S = 60.0
log = farmvm.log


def serving_after(admin, t0, render_ranks, timeout, alive):
    """Host time of the admin's first 'serving ... (N render ranks' line after t0; None if none came."""
    rx = re.compile(rf"follow .*serving .*\({render_ranks} render ranks")
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and alive():
        admin.pump()
        for t, text in admin.marks:
            if t > t0 and rx.match(text):
                return t
        time.sleep(0.5)
    return None


def first_frame_after(frames, t_real):
    """Seconds from t_real (host CLOCK_REALTIME) to the first frame requested after it and shown."""
    later = [f["presented_ns"] / 1e9 for f in frames if f["request_ns"] / 1e9 > t_real]
    return round(min(later) - t_real, 1) if later else None


def start_kiosk(net, kiosk, toml, kdir):
    os.makedirs(kdir, exist_ok=True)
    stats = os.path.join(kdir, "stats.json")
    logf = open(os.path.join(kdir, "kiosk.log"), "w")
    p = subprocess.Popen(net.prefix() + [kiosk, "--config", toml, "--duration-s", "3000", "--stats", stats],
                         stdout=logf, stderr=subprocess.STDOUT, start_new_session=True)
    return p, stats


def stop_kiosk(p):
    if p.poll() is None:
        os.killpg(p.pid, signal.SIGTERM)
    try:
        p.wait(timeout=60)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        p.wait()


def run(net, vms, host, image, work, kiosk, toml, results, fails):
    """host: (name, tap, mac, memory MiB) of the render host to lose. Replaces vms[name] by the
    rebooted VM (left running: the caller stops every VM)."""
    name, tap, mac, mem = host
    admin = vms["farm-admin"].serial
    admin_alive = lambda: vms["farm-admin"].proc.poll() is None  # noqa: E731
    proc, stats = start_kiosk(net, kiosk, toml, os.path.join(work, "kiosk-host-loss"))
    events = {}
    try:
        time.sleep(20)  # frames on the wall before the first loss
        # 1. the link cut, then restored
        t0, r0 = time.monotonic(), time.time()
        net.ip("link", "set", tap, "down")
        events["link_cut"] = r0
        t1 = serving_after(admin, t0, 1, 300, admin_alive)
        results["host_loss_link_serving_1_s"] = round(t1 - t0, 1) if t1 else None
        time.sleep(15)
        t2 = time.monotonic()
        net.ip("link", "set", tap, "up")
        t3 = serving_after(admin, t2, 2, 400, admin_alive)
        results["host_loss_link_back_s"] = round(t3 - t2, 1) if t3 else None
        time.sleep(15)
        # 2. the VM killed (power cut), then booted again from its disk
        t4, r4 = time.monotonic(), time.time()
        vms[name].proc.kill()
        vms[name].proc.wait()
        events["vm_killed"] = r4
        t5 = serving_after(admin, t4, 1, 300, admin_alive)
        results["host_loss_vm_serving_1_s"] = round(t5 - t4, 1) if t5 else None
        time.sleep(10)
        vms[name] = vm = farmvm.start_vm(net, tap, mac, image, mem, os.path.join(work, f"{name}-rebooted"), name)
        t6, _ = vm.serial.wait(r"ok sshd-active", 900, lambda: vm.proc.poll() is None)
        if t6 is not None:
            t7 = serving_after(admin, t6, 2, 400, admin_alive)
            results["host_loss_vm_back_s"] = round(t7 - t6, 1) if t7 else None
        time.sleep(10)
    finally:
        stop_kiosk(proc)
    try:
        with open(stats) as f:
            frames = json.load(f).get("frames", [])
    except (OSError, ValueError) as e:
        frames = []
        log(f"host-loss kiosk statistics unreadable: {e}")
    if "link_cut" in events:
        results["host_loss_link_new_frame_s"] = first_frame_after(frames, events["link_cut"])
    if "vm_killed" in events:
        results["host_loss_vm_new_frame_s"] = first_frame_after(frames, events["vm_killed"])
    for what, key in (("link cut", "link"), ("VM killed", "vm")):
        new = results.get(f"host_loss_{key}_new_frame_s")
        back = results.get(f"host_loss_{key}_back_s")
        fails.check(new is not None, f"{name} {what}: a new frame on the wall {new} s after the loss "
                                     f"(goal {NEW_FRAME_GOAL_S:.0f} s)")
        fails.check(back is not None, f"{name} {what}: rank 2 back {back} s after the host returned "
                                      f"(goal {BACK_GOAL_S:.0f} s)")
