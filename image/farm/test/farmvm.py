# SPDX-License-Identifier: Apache-2.0
"""QEMU, serial console and network-namespace helpers of farm_qemu_test.py (python3 stdlib only)."""
import json
import os
import re
import shutil
import socket
import subprocess
import sys
import time

# The helpers both QEMU tests share live beside the appliance's test (image/test/qemu_common.py).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "test"))
from qemu_common import T0, Failures, Serial, log, set_name  # noqa: E402,F401 (re-exported to farm_qemu_test.py)

set_name("farm_qemu_test")

OVMF_CODE = "/usr/share/OVMF/OVMF_CODE_4M.fd"
OVMF_VARS = "/usr/share/OVMF/OVMF_VARS_4M.fd"
# Listeners a render host may have besides the farm's port and sshd: Open MPI's daemons (mpirun,
# orted: any port, their out-of-band channel) and ranks (the BTL port range of
# image/farm/rootfs/etc/openmpi/openmpi-mca-params.conf; PMIx on loopback).
MPI_PORTS = range(46000, 46100)
MPI_DAEMONS = {"mpirun", "orterun", "orted"}


def missing_tools():
    """Why the test cannot run here (a message), or None."""
    for tool, pkg in (("qemu-system-x86_64", "qemu-system-x86"), ("mcopy", "mtools"), ("debugfs", "e2fsprogs"),
                      ("sfdisk", "fdisk"), ("ip", "iproute2"), ("ssh-keygen", "openssh-client")):
        if not shutil.which(tool):
            return f"{tool} not found (apt-get install {pkg})"
    for f in (OVMF_CODE, OVMF_VARS):
        if not os.path.exists(f):
            return f"{f} not found (apt-get install ovmf)"
    if not os.path.exists("/dev/net/tun"):
        return "/dev/net/tun missing (no tap networking here)"
    probe = f"mogao-farmprobe-{os.getpid()}"
    r = subprocess.run(["ip", "netns", "add", probe], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if r.returncode != 0:
        return f"cannot create a network namespace: {r.stdout.strip()}"
    r = subprocess.run(["ip", "netns", "exec", probe, "ip", "tuntap", "add", "dev", "tap0", "mode", "tap"],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    subprocess.run(["ip", "netns", "delete", probe])
    if r.returncode != 0:
        return f"cannot create a tap device in a network namespace: {r.stdout.strip()}"
    return None


def fields(text):
    """The k=v words of a marker as a dict (values up to the next space; quotes not parsed)."""
    return dict(w.split("=", 1) for w in (text or "").split() if "=" in w)


def parse_ranks(text):
    """The 'pid:uid:rank:seccomp:nnp' words of selftest.sh's ranks() output."""
    out = []
    for w in (text or "").split():
        m = re.fullmatch(r"(?:ranks=)?(\d+):(\d+):(\d*):(\d*):(\d*)", w)
        if m:
            out.append(dict(zip(("pid", "uid", "rank", "seccomp", "nnp"), m.groups())))
    return out


def unexpected_listeners(listen, farm_port):
    """Entries of ['tcp'|'udp', 'addr:port', 'program'] that are none of: mogao-farm on farm_port
    or in MPI_PORTS, sshd on 22, an Open MPI daemon, anything of theirs on loopback."""
    bad = []
    for entry in listen:
        if len(entry) < 3:
            bad.append(" ".join(entry))
            continue
        proto, addr, prog = entry[0], entry[1], entry[2]
        port = int(addr.rsplit(":", 1)[1]) if addr.rsplit(":", 1)[-1].isdigit() else -1
        loopback = addr.startswith("127.") or addr.startswith("[::1]")
        if proto == "tcp" and ((prog == "mogao-farm" and (port == farm_port or port in MPI_PORTS or loopback))
                               or (prog == "sshd" and port == 22) or prog in MPI_DAEMONS):
            continue
        bad.append(" ".join(entry))
    return bad


def serial_console_entry(img, work):
    """The loader entry of the copy IMG gets the kernel and systemd messages on ttyS0 (test only)."""
    env = dict(os.environ, MTOOLS_SKIP_CHECK="1")
    esp = f"{img}@@1M"
    entry = subprocess.run(["mtype", "-i", esp, "::/loader/entries/mogao.conf"], check=True, env=env,
                           stdout=subprocess.PIPE, text=True).stdout
    entry = re.sub(r"^options (.*)$", lambda m: "options " + " ".join(
        w for w in m.group(1).split() if not re.fullmatch(r"quiet|loglevel=\d", w)) + " console=ttyS0,115200",
        entry, flags=re.M)
    path = os.path.join(work, "mogao.conf")
    with open(path, "w") as f:
        f.write(entry)
    subprocess.run(["mcopy", "-o", "-i", esp, path, "::/loader/entries/mogao.conf"], check=True, env=env)


class Netns:
    """A network namespace with a bridge br0 (the host's addresses) and N taps on it."""

    def __init__(self, name, addrs, taps):
        self.name, self.addrs, self.taps = name, addrs, taps
        self.created = False

    def ip(self, *args):
        subprocess.run(["ip", "netns", "exec", self.name, "ip", *args], check=True)

    def up(self):
        subprocess.run(["ip", "netns", "add", self.name], check=True)
        self.created = True
        self.ip("link", "set", "lo", "up")
        self.ip("link", "add", "br0", "type", "bridge")
        for i in range(self.taps):
            self.ip("tuntap", "add", "dev", f"tap{i}", "mode", "tap")
            self.ip("link", "set", f"tap{i}", "master", "br0")
            self.ip("link", "set", f"tap{i}", "up")
        for addr in self.addrs:
            # nodad: the address is usable at once (no duplicate detection on a private bridge).
            self.ip("addr", "add", addr, "dev", "br0", *(["nodad"] if ":" in addr else []))
        self.ip("link", "set", "br0", "up")

    def prefix(self):
        return ["ip", "netns", "exec", self.name]

    def run(self, cmd, logfile, timeout):
        """Runs cmd inside the namespace, output to logfile; returns its exit code (None: killed)."""
        with open(logfile, "w") as f:
            p = subprocess.Popen(self.prefix() + cmd, stdout=f, stderr=subprocess.STDOUT, start_new_session=True)
            try:
                return p.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, 9)
                p.wait()
                return None

    def tcp_probe(self, src, dst, port, timeout_s=4.0):
        """A TCP connection from the namespace's address src to dst:port: "open", "refused" (RST: no
        listener, no filter), "timeout" (dropped: a packet filter) or "error:<reason>"."""
        code = ("import socket, sys\n"
                "src, dst, port, t = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4])\n"
                "s = socket.socket(socket.AF_INET6 if ':' in dst else socket.AF_INET, socket.SOCK_STREAM)\n"
                "s.settimeout(t)\n"
                "s.bind((src, 0))\n"
                "try:\n"
                "    s.connect((dst, port)); print('open')\n"
                "except socket.timeout:\n"
                "    print('timeout')\n"
                "except ConnectionRefusedError:\n"
                "    print('refused')\n"
                "except OSError as e:\n"
                "    print('error:' + (e.strerror or str(e)))\n")
        r = subprocess.run(self.prefix() + ["python3", "-c", code, src, dst, str(port), str(timeout_s)],
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=timeout_s + 30)
        return r.stdout.strip().splitlines()[-1] if r.stdout.strip() else f"error:exit {r.returncode}"

    def down(self):
        if self.created:
            subprocess.run(["ip", "netns", "delete", self.name])
            self.created = False


class Vm:
    def __init__(self, proc, serial, ctl, logfile):
        self.proc, self.serial, self.ctl, self.logfile = proc, serial, ctl, logfile

    def tell(self, line):
        self.ctl.sendall(line.encode() + b"\n")


def start_vm(net, tap, mac, img, mem_mib, vdir, name):
    """QEMU (q35, OVMF, TCG) on the copy IMG, its NIC on the namespace's tap; serial port 1 logged
    to VDIR/serial.log, serial port 2 the host's answers."""
    os.makedirs(vdir, exist_ok=True)
    vars_fd = os.path.join(vdir, "OVMF_VARS.fd")
    shutil.copy(OVMF_VARS, vars_fd)
    serial_log, ctl_sock = os.path.join(vdir, "serial.log"), os.path.join(vdir, "ctl.sock")
    for p in (serial_log, ctl_sock):
        if os.path.exists(p):
            os.remove(p)
    cmd = net.prefix() + [
        "qemu-system-x86_64", "-name", name, "-nodefaults", "-machine", "q35", "-m", str(mem_mib), "-smp", "2",
        # TCG: nested KVM guests print nothing on these machines.
        "-accel", "tcg", "-cpu", "max",
        "-drive", f"if=pflash,format=raw,readonly=on,file={OVMF_CODE}",
        "-drive", f"if=pflash,format=raw,file={vars_fd}",
        "-drive", f"if=virtio,format=raw,file={img}",
        "-netdev", f"tap,id=n0,ifname={tap},script=no,downscript=no",
        "-device", f"virtio-net-pci,netdev=n0,mac={mac}",
        "-display", "none", "-serial", f"file:{serial_log}", "-serial", f"unix:{ctl_sock},server=on,wait=off"]
    log(f"{name}: starting QEMU: {' '.join(cmd)}")
    logfile = open(os.path.join(vdir, "qemu.log"), "w")
    proc = subprocess.Popen(cmd, stdout=logfile, stderr=subprocess.STDOUT)
    ctl = socket.socket(socket.AF_UNIX)
    deadline = time.monotonic() + 60
    while True:
        try:
            ctl.connect(ctl_sock)
            break
        except OSError:
            if time.monotonic() > deadline or proc.poll() is not None:
                raise RuntimeError(f"{name}: QEMU did not start (see {vdir}/qemu.log)")
            time.sleep(0.2)
    return Vm(proc, Serial(serial_log, name), ctl, logfile)


def stop_vm(vm):
    if vm.proc.poll() is None:
        vm.proc.terminate()
        try:
            vm.proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            vm.proc.kill()
            vm.proc.wait()
    vm.logfile.close()


def image_stats(tool, path):
    """(mean code, dark fraction) of a PNG/PPM by mogao_kiosk_image_tool stats, or None."""
    if not tool or not os.access(tool, os.X_OK):
        return None
    r = subprocess.run([tool, "stats", path], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    parts = r.stdout.split()
    return (float(parts[-2]), float(parts[-1])) if r.returncode == 0 and len(parts) >= 5 else None


def ppm_stats(path):
    """(mean code, fraction of pixels with every channel <= 8) of a binary PPM (P6, 8 bit)."""
    with open(path, "rb") as f:
        data = f.read()
    m = re.match(rb"P6\s+(?:#[^\n]*\n\s*)*(\d+)\s+(\d+)\s+255\s", data)
    if not m:
        raise ValueError(f"{path}: not an 8-bit P6 PPM")
    w, h = int(m.group(1)), int(m.group(2))
    px = data[m.end():m.end() + w * h * 3]
    dark = sum(1 for i in range(0, len(px), 3) if px[i] <= 8 and px[i + 1] <= 8 and px[i + 2] <= 8)
    return sum(px) / max(1, len(px)), dark / max(1, w * h)


def kiosk_results(kdir, stats_file, t_start, tool):
    """Figures of the host kiosk's run: connection, frames, first-frame time, the last farm frame's
    brightness (content dump, PPM) and the last output PNG's."""
    res = {}
    try:
        with open(stats_file) as f:
            st = json.load(f)
    except (OSError, ValueError) as e:
        log(f"no kiosk statistics ({stats_file}): {e}")
        st = {}
    res["kiosk_frames"] = st.get("frames_presented", 0)
    connected = [ev["time_ns"] for ev in st.get("events", []) if ev.get("event") == "connected"]
    if connected:
        res["kiosk_connected_s"] = round(connected[0] / 1e9 - t_start, 2)
    frames = st.get("frames", [])
    if frames:
        res["kiosk_first_frame_s"] = round(min(f["presented_ns"] for f in frames) / 1e9 - t_start, 2)
        res["kiosk_motion_to_photon_ms_mean"] = round(sum(f["motion_to_photon_ms"] for f in frames) / len(frames), 1)
    with open(os.path.join(kdir, "kiosk.log"), errors="replace") as f:
        klog = f.read()
    if "kiosk_connected_s" not in res and re.search(r"farm \S+ connected", klog):
        res["kiosk_connected_s"] = -1.0   # connected (log), time unknown
    dumps = sorted(p for p in os.listdir(os.path.join(kdir, "content")) if p.endswith(".ppm"))
    if dumps:
        mean, dark = ppm_stats(os.path.join(kdir, "content", dumps[-1]))
        res["content_mean"], res["content_dark"] = round(mean, 1), round(dark, 3)
        res["content_frame"] = os.path.join(kdir, "content", dumps[-1])
    pngs = sorted(p for p in os.listdir(os.path.join(kdir, "png")) if p.endswith(".png"))
    if pngs:
        s = image_stats(tool, os.path.join(kdir, "png", pngs[-1]))
        if s:
            res["output_mean"], res["output_dark"] = round(s[0], 1), round(s[1], 3)
    return res
