# SPDX-License-Identifier: Apache-2.0
"""QEMU's machine protocol (QMP) for the QEMU tests, and the PPM screendumps they ask it for
(`screendump` of each virtio-gpu head). python3 stdlib only.

    qmp = Qmp("/tmp/qmp.sock")
    qmp.cmd("screendump", filename="head0.ppm", device="video0", head=0)
    width, height, mean, dark = ppm_stats("head0.ppm")
"""
import json
import socket
import time


# --- images -----------------------------------------------------------------------------------------
def read_ppm(path):
    with open(path, "rb") as f:
        data = f.read()
    fields = []
    pos = 0
    while len(fields) < 4:
        while data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b"#":
            pos = data.index(b"\n", pos) + 1
            continue
        start = pos
        while not data[pos:pos + 1].isspace():
            pos += 1
        fields.append(data[start:pos])
    if fields[0] != b"P6" or int(fields[3]) != 255:
        raise ValueError(f"{path}: not an 8-bit P6 PPM")
    w, h = int(fields[1]), int(fields[2])
    return w, h, data[pos + 1:pos + 1 + w * h * 3]


def ppm_stats(path, x_from=0):
    """(width, height, mean code, fraction of pixels with max channel < 16) of the columns >= x_from."""
    w, h, px = read_ppm(path)
    step = 7  # sample every 7th pixel of a row: plenty for "is it lit"
    total = dark = count = 0
    for y in range(h):
        for x in range(x_from, w, step):
            i = y * w + x
            r, g, b = px[3 * i], px[3 * i + 1], px[3 * i + 2]
            total += r + g + b
            dark += max(r, g, b) < 16
            count += 1
    if count == 0:
        return w, h, 0.0, 1.0
    return w, h, total / (3 * count), dark / count


# --- QMP ----------------------------------------------------------------------------------------------
class Qmp:
    def __init__(self, path, timeout=60):
        deadline = time.monotonic() + timeout
        while True:
            try:
                self.sock = socket.socket(socket.AF_UNIX)
                self.sock.connect(path)
                break
            except OSError:
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.2)
        self.buf = b""
        self.events = []
        self._read()  # greeting
        self.cmd("qmp_capabilities")

    def _read(self, timeout=120):
        self.sock.settimeout(timeout)
        while b"\n" not in self.buf:
            chunk = self.sock.recv(65536)
            if not chunk:
                raise EOFError("QMP closed")
            self.buf += chunk
        line, self.buf = self.buf.split(b"\n", 1)
        return json.loads(line)

    def cmd(self, name, **arguments):
        msg = {"execute": name}
        if arguments:
            msg["arguments"] = arguments
        self.sock.sendall(json.dumps(msg).encode() + b"\n")
        while True:
            reply = self._read()
            if "event" in reply:
                self.events.append(reply)
                continue
            if "error" in reply:
                raise RuntimeError(f"QMP {name}: {reply['error']}")
            return reply.get("return")

    def poll_events(self, timeout):
        """Collects events for up to `timeout` seconds; returns all seen so far (False on EOF)."""
        deadline = time.monotonic() + timeout
        try:
            while time.monotonic() < deadline:
                try:
                    self.events.append(self._read(timeout=max(0.1, deadline - time.monotonic())))
                except socket.timeout:
                    break
        except (EOFError, OSError):
            return False
        return True
