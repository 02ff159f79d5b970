#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Starts a Type=notify unit of a root file system the way systemd would, where systemd cannot
boot that root (farm_package_test.sh): chroot into ROOT, run each ExecStartPre (a "+" one as root,
"-" ones may fail), then ExecStart as the unit's User= and Group= with its Environment= and
EnvironmentFile= variables expanded as systemd expands them (${X}: one word, $X: split on blanks),
RUNTIME_DIRECTORY and STATE_DIRECTORY made, and a NOTIFY_SOCKET. Waits for READY=1, checks that a
TCP PORT listens, runs CLIENT (a command in ROOT, as root) while the unit serves, then stops the
process group with SIGTERM.

Not reproduced: the unit's sandbox (ProtectSystem=, PrivateTmp=, the system call filter...), its
watchdog and restarts; systemd-analyze verify and the QEMU render-host test cover those.

  unit_start.py ROOT UNIT PORT [TIMEOUT_S [CLIENT...]]
                                exit 0: READY, listening and CLIENT's exit 0; 1 otherwise
"""
import os
import re
import shlex
import signal
import socket
import subprocess
import sys
import time


def unit_settings(text):
    """[Service] settings as (key, value) in order, continuation lines joined."""
    text = re.sub(r"\\\n[ \t]*", " ", text)
    section, out = None, []
    for line in text.splitlines():
        line = line.strip()
        if not line or line[0] in "#;":
            continue
        if line.startswith("["):
            section = line
        elif section == "[Service]" and "=" in line:
            key, value = line.split("=", 1)
            out.append((key.strip(), value.strip()))
    return out


def read_env_file(path):
    env = {}
    with open(path) as f:
        for line in f:
            line = line.strip()
            if line and not line.startswith("#") and "=" in line:
                key, value = line.split("=", 1)
                env[key.strip()] = " ".join(shlex.split(value)) if value.strip() else ""
    return env


def expand(command, env):
    """systemd's expansion of ExecStart (systemd.service(5), "Command lines")."""
    words = []
    for word in shlex.split(command.replace("$$", "\0")):
        m = re.fullmatch(r"\$([A-Za-z_][A-Za-z0-9_]*)", word)
        if m:
            words += env.get(m.group(1), "").split()
            continue
        words.append(re.sub(r"\$\{([A-Za-z_][A-Za-z0-9_]*)\}", lambda g: env.get(g.group(1), ""),
                            word).replace("\0", "$"))
    return words


def chroot_cmd(root, argv, user=None, env=None):
    prefix = ["chroot", root]
    if user:
        prefix += ["setpriv", f"--reuid={user}", f"--regid={user}", "--init-groups", "--"]
    return prefix + ["/usr/bin/env", "-i"] + [f"{k}={v}" for k, v in (env or {}).items()] + argv


def main():
    root, unit, port = sys.argv[1], sys.argv[2], int(sys.argv[3])
    timeout = float(sys.argv[4]) if len(sys.argv) > 4 else 180.0
    client = sys.argv[5:]
    settings = unit_settings(open(os.path.join(root, unit.lstrip("/"))).read())
    env = {"PATH": "/usr/sbin:/usr/bin:/sbin:/bin", "LC_ALL": "C.UTF-8"}
    user = group = None
    for key, value in settings:
        if key == "Environment":
            env.update(dict(kv.split("=", 1) for kv in shlex.split(value)))
        elif key == "EnvironmentFile":
            path = os.path.join(root, value.lstrip("-").lstrip("/"))
            if os.path.exists(path):
                env.update(read_env_file(path))
            elif not value.startswith("-"):
                sys.exit(f"FAIL: EnvironmentFile {value} missing")
        elif key == "User":
            user = value
        elif key == "Group":
            group = value
        elif key in ("RuntimeDirectory", "StateDirectory"):
            base = "run" if key == "RuntimeDirectory" else "var/lib"
            path = os.path.join(root, base, value)
            os.makedirs(path, exist_ok=True)
            subprocess.run(chroot_cmd(root, ["chown", f"{user}:{group or user}", f"/{base}/{value}"]), check=True)
            env[key.upper().replace("DIRECTORY", "_DIRECTORY")] = f"/{base}/{value}"
    for key, value in settings:
        if key != "ExecStartPre":
            continue
        flags = re.match(r"[-+@:!]*", value).group(0)
        argv = expand(value[len(flags):], env)
        rc = subprocess.run(chroot_cmd(root, argv, None if "+" in flags else user, env)).returncode
        print(f"ExecStartPre{' (as root)' if '+' in flags else ''}: {' '.join(argv)} -> exit {rc}")
        if rc != 0 and "-" not in flags:
            sys.exit(f"FAIL: ExecStartPre {argv} exit {rc}")
    start = next(v for k, v in settings if k == "ExecStart")
    argv = expand(start, env)
    sock_path = "/run/unit-start-notify.sock"
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    host_sock = os.path.join(root, sock_path.lstrip("/"))
    if os.path.exists(host_sock):
        os.unlink(host_sock)
    sock.bind(host_sock)
    os.chmod(host_sock, 0o777)
    env["NOTIFY_SOCKET"] = sock_path
    print(f"ExecStart as {user}: {' '.join(argv)}")
    proc = subprocess.Popen(chroot_cmd(root, argv, user, env), start_new_session=True)
    ready = False
    deadline = time.monotonic() + timeout
    sock.settimeout(1.0)
    try:
        while time.monotonic() < deadline and proc.poll() is None:
            try:
                msg = sock.recv(4096).decode(errors="replace")
            except socket.timeout:
                continue
            if "READY=1" in msg.split("\n"):
                ready = True
                print(f"READY=1 after {timeout - (deadline - time.monotonic()):.1f} s")
                break
        listening = ready and listening_on(port)
        print(f"listening on TCP port {port}: {listening}")
        if not (ready and listening):
            return 1
        if client:
            client_env = {"PATH": env["PATH"], "LC_ALL": "C.UTF-8", "HOME": "/root"}
            rc = subprocess.run(chroot_cmd(root, client, None, client_env)).returncode
            print(f"client {' '.join(client)}: exit {rc}")
            return 0 if rc == 0 else 1
        return 0
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGTERM)
            try:
                proc.wait(timeout=15)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
        else:
            print(f"FAIL: the farm exited with {proc.returncode} before READY=1")
        sock.close()
        os.unlink(host_sock)


def listening_on(port):
    """A TCP socket in LISTEN state on PORT (IPv4 or IPv6), from /proc/net (no ss needed)."""
    for table in ("/proc/net/tcp6", "/proc/net/tcp"):
        try:
            lines = open(table).read().splitlines()[1:]
        except OSError:
            continue
        for line in lines:
            fields = line.split()
            if fields[3] == "0A" and int(fields[1].rsplit(":", 1)[1], 16) == port:
                return True
    return False


if __name__ == "__main__":
    sys.exit(main())
