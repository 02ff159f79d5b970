# SPDX-License-Identifier: Apache-2.0
"""What the QEMU tests share (image/test/qemu_boot_test.py, image/farm/test/farm_qemu_test.py):
timestamped logging, PASS/FAIL bookkeeping and the serial-console marker reader. python3 stdlib only.

The guests' self-test scripts print `MOGAO-SELFTEST <text>` lines on the serial console; Serial
follows the console's log file and collects them with the host time at which they were read.
"""
import re
import subprocess
import time

T0 = time.monotonic()
# image/build's ESP: slot a's loader entry, kernel and initramfs (docs/updates.md; slot b's appear
# with the first update).
IMAGE_ENTRY = "::/loader/entries/mogao-1-a.conf"
IMAGE_KERNEL = "/mogao/a/vmlinuz"
IMAGE_INITRD = "/mogao/a/initrd.img"
_name = "qemu_test"


def stop_qemu(proc, grace_s=20):
    """Ends QEMU (SIGTERM, then SIGKILL after grace_s) unless it has ended already."""
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=grace_s)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def set_name(name):
    """The prefix of log lines: the test's name."""
    global _name
    _name = name


def log(msg):
    print(f"[{_name} {time.monotonic() - T0:7.1f}s] {msg}", flush=True)


class Failures:
    """Each check is logged as PASS or FAIL; the failed ones are kept for the results."""

    def __init__(self):
        self.items = []

    def check(self, cond, what):
        log(("PASS " if cond else "FAIL ") + what)
        if not cond:
            self.items.append(what)
        return cond


class Serial:
    """Follows a serial log file; collects MOGAO-SELFTEST lines (logged as `<name>: <text>`)."""

    MARK = re.compile(r"MOGAO-SELFTEST (.*)")

    def __init__(self, path, name="guest"):
        self.path, self.name = path, name
        self.pos = 0
        self.partial = ""
        self.marks = []   # (host time, text)

    def pump(self):
        try:
            with open(self.path, "rb") as f:
                f.seek(self.pos)
                data = f.read()
                self.pos += len(data)
        except FileNotFoundError:
            return
        lines = (self.partial + data.decode("utf-8", "replace")).split("\n")
        self.partial = lines.pop()
        now = time.monotonic()
        for line in lines:
            m = self.MARK.search(line)
            if m:
                self.marks.append((now, m.group(1).strip()))
                log(f"{self.name}: {m.group(1).strip()}")

    def wait(self, pattern, timeout, alive):
        """Waits for a marker matching `pattern` (regex, from its start); returns (time, text), or
        (None, None) after `timeout` seconds or once alive() is false (QEMU ended)."""
        rx = re.compile(pattern)
        deadline = time.monotonic() + timeout
        while True:
            self.pump()
            for t, text in self.marks:
                if rx.match(text):
                    return t, text
            if time.monotonic() > deadline or not alive():
                return None, None
            time.sleep(0.5)

    def tail(self, n=60):
        try:
            with open(self.path, "rb") as f:
                return "\n".join(f.read().decode("utf-8", "replace").splitlines()[-n:])
        except FileNotFoundError:
            return ""
