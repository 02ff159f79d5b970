#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Rewrites the measured table of docs/services.md ("QEMU test of the farm unit") from the results
of one run of farm_qemu_test.py, so that its figures are never pasted by hand.

    image/farm/test/results_table.py build/image/farm-qemu-test-results.json [--doc docs/services.md]
    image/farm/test/results_table.py --check     # CTest: a sample run into a copy of the doc

The table sits between `<!-- generated:farm-qemu -->` and `<!-- /generated -->`; the rest of the
doc is kept. A run with failures is refused (its figures describe a broken farm). Python 3 stdlib.
"""
import argparse
import json
import os
import re
import shutil
import sys
import tempfile

START, END = "<!-- generated:farm-qemu -->", "<!-- /generated -->"
SAMPLE = {"layout": "both", "date": "2026-01-01", "commit": "abc1234", "host_cpus": 2, "image_build_s": 70.0,
          "image_bytes": 764411904, "image_allocated_bytes": 350269440, "farm-admin_qemu_start_to_selftest_s": 58.5,
          "farm-render2_qemu_start_to_selftest_s": 59.0, "host_qemu_start_to_farm_ready_s": 81.5,
          "guest_boot_to_farm_ready_s": 67.4, "guest_exec_to_farm_ready_s": 18.5, "restarts_before_ready": 0,
          "admin_ranks": [{"rank": "0"}, {"rank": "1"}], "render2_ranks": [{"rank": "2"}],
          "kiosk_connected_s": 0.7, "kiosk_first_frame_s": 11.8, "kiosk_frames": 4,
          "farm-admin_package_install_s": 21.0, "farm-render2_package_install_s": 20.5,
          "watchdog_stop_to_kill_s": 43.7, "watchdog_stop_to_active_again_s": 69.5, "security_online_exposure": 1.6,
          "test_seconds": 247.7, "failures": []}


def seconds(r, key):
    return f"{r[key]:.1f} s" if isinstance(r.get(key), (int, float)) else "not measured"


def ranks(rs):
    return ", ".join(sorted(x.get("rank", "?") for x in rs)) or "none"


def table(r):
    """The marker block's body: where and when, then one row per figure."""
    lines = [f"Measured {r.get('date', '?')} at commit {r.get('commit', '?')} ({r.get('host_cpus', '?')} host "
             f"cores, both VMs under TCG, `--layout {r.get('layout', '?')}`; "
             "`image/farm/test/results_table.py build/image/farm-qemu-test-results.json`):", "",
             "| what | figure |", "|---|---|"]
    build = seconds(r, "image_build_s")
    lines.append(f"| image | built in {build}; {r['image_bytes'] / 1e6:.0f} MB, "
                 f"{r['image_allocated_bytes'] / 1e6:.0f} MB allocated |")
    lines.append(f"| ranks | farm-admin: {ranks(r.get('admin_ranks', []))}; "
                 f"farm-render2: {ranks(r.get('render2_ranks', []))} |")
    lines.append(f"| `apt install ./mogao-farm_*.deb` (offline) | farm-admin "
                 f"{seconds(r, 'farm-admin_package_install_s')}, farm-render2 "
                 f"{seconds(r, 'farm-render2_package_install_s')} |")
    lines.append(f"| QEMU start to self-test | farm-admin {seconds(r, 'farm-admin_qemu_start_to_selftest_s')}, "
                 f"farm-render2 {seconds(r, 'farm-render2_qemu_start_to_selftest_s')} |")
    lines.append(f"| READY | {seconds(r, 'guest_boot_to_farm_ready_s')} after boot (guest clock), "
                 f"{seconds(r, 'guest_exec_to_farm_ready_s')} after ExecStart, "
                 f"{seconds(r, 'host_qemu_start_to_farm_ready_s')} after QEMU started; "
                 f"restarts before READY: {r.get('restarts_before_ready', '?')} |")
    lines.append(f"| host kiosk (IPv6 + mutual TLS) | connected {seconds(r, 'kiosk_connected_s')} and first farm frame "
                 f"{seconds(r, 'kiosk_first_frame_s')} after its start; {r.get('kiosk_frames', 0)} frames |")
    lines.append(f"| SIGSTOPped admin rank | watchdog kill {seconds(r, 'watchdog_stop_to_kill_s')}, active again "
                 f"{seconds(r, 'watchdog_stop_to_active_again_s')} after the stop |")
    if any(k.startswith("host_loss_") for k in r):
        lines.append(f"| farm-render2's link cut while serving | new frame on the wall "
                     f"{seconds(r, 'host_loss_link_new_frame_s')}, "
                     f"admin serving on 1 render rank {seconds(r, 'host_loss_link_serving_1_s')} after the cut; "
                     f"rank 2 serving again {seconds(r, 'host_loss_link_back_s')} after the link came back |")
        lines.append(f"| farm-render2's VM killed while serving | new frame on the wall "
                     f"{seconds(r, 'host_loss_vm_new_frame_s')}, "
                     f"admin serving on 1 render rank {seconds(r, 'host_loss_vm_serving_1_s')} after the kill; "
                     f"rank 2 serving again {seconds(r, 'host_loss_vm_back_s')} after the rebooted host's "
                     f"sshd was up |")
    else:
        lines.append("| render host lost while serving | not measured in this run (`--host-loss`) |")
    lines.append(f"| `systemd-analyze security` online | {r.get('security_online_exposure', '?')} |")
    lines.append(f"| test wall time | {seconds(r, 'test_seconds')} (+ {build} image build) |")
    return "\n".join(lines)


def rewrite(doc, results):
    text = open(doc).read()
    m = re.search(re.escape(START) + r"\n.*?" + re.escape(END), text, re.S)
    if not m:
        sys.exit(f"{doc}: no '{START}' ... '{END}' block")
    open(doc + ".tmp", "w").write(text[:m.start()] + START + "\n" + table(results) + "\n" + END + text[m.end():])
    os.replace(doc + ".tmp", doc)


def main():
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("results", nargs="?")
    ap.add_argument("--doc", default=os.path.join(root, "docs", "services.md"))
    ap.add_argument("--check", action="store_true")
    a = ap.parse_args()
    if a.check:
        with tempfile.TemporaryDirectory() as tmp:
            copy = os.path.join(tmp, "services.md")
            shutil.copy(a.doc, copy)
            rewrite(copy, SAMPLE)
            before, after = open(a.doc).read(), open(copy).read()
            outside = lambda t: re.sub(re.escape(START) + r".*?" + re.escape(END), "", t, flags=re.S)
            if outside(before) != outside(after) or "abc1234" not in after:
                sys.exit("results_table: the rewrite changed text outside the markers or wrote nothing")
        print("results_table: the farm-qemu block rewrites cleanly")
        return
    if not a.results:
        ap.error("give the results JSON (or --check)")
    r = json.load(open(a.results))
    if r.get("failures"):
        sys.exit(f"{a.results}: the run had {len(r['failures'])} failure(s); its figures are not written")
    rewrite(a.doc, r)
    print(f"{a.doc}: farm-qemu table from {a.results}")


if __name__ == "__main__":
    main()
