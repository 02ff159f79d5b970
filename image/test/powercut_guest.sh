#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# Runs INSIDE the appliance under QEMU as PID 1 (init=/powercut-init on the kernel command line of
# image/test/qemu_powercut_test.py, written onto the test copy's root; the shipped image contains
# nothing of this). The image's own kernel, initramfs and root file system; no systemd, so that a
# boot after a power cut costs seconds under TCG, not a minute.
#
# Every boot: the configuration partition is checked and mounted as the appliance's fstab and
# systemd-fsck do (fsck -p, then rw,nosuid,nodev,noexec,noatime on /var/lib/mogao, its etc/
# bound read-only on /etc/mogao), and the files the writes under test touch are reported:
#   MOGAO-SELFTEST file <path> <sha256|missing> <bytes>
#   MOGAO-SELFTEST temp <path> <bytes>        (a leftover temporary of an interrupted write)
#   MOGAO-SELFTEST state-done
# Then it waits for the host's command on the second serial port:
#   calibrate   mogao-calibrate --install from the test disk's captures; frozen (SIGSTOP) as soon as
#               its write phase begins (its first file in --out), "frozen" printed; on the next line
#               from the host ("go") it continues
#   config      the kiosk's start-up on a changed kiosk.toml and MPCDI, which copies both to their
#               last good copies (kiosk/config/last_loaded.h); "frozen" before it starts, "go" starts it
# While the program runs, each change of the watched folder is printed with the guest's uptime
#   MOGAO-SELFTEST ev <uptime> <file names>
# and its end as "exit rc=<rc> <uptime>"; then everything is synced and it waits for a command again.
# The host cuts the power (QMP system_reset) at a random point after "go".
export PATH=/usr/sbin:/usr/bin:/sbin:/bin
out=/dev/ttyS0
ctl=/dev/ttyS1
cfg=/var/lib/mogao
say() { echo "MOGAO-SELFTEST $*" > "$out"; }
uptime_s() { local up _; read -r up _ < /proc/uptime; echo "$up"; }

mount -t proc proc /proc 2>/dev/null
mount -t sysfs sysfs /sys 2>/dev/null
mount -t devtmpfs devtmpfs /dev 2>/dev/null
mount -t tmpfs tmpfs /run
mount -t tmpfs tmpfs /tmp
say "boot uptime=$(uptime_s)"
fsck.ext4 -p /dev/vda3 > /tmp/fsck.log 2>&1
say "fsck rc=$? $(tr '\n' ' ' < /tmp/fsck.log | cut -c1-200)"
if ! mount -t ext4 -o rw,nosuid,nodev,noexec,noatime /dev/vda3 "$cfg"; then say "FAIL mount"; fi
mount --bind "$cfg/etc" /etc/mogao && mount -o remount,bind,ro /etc/mogao
mount -o ro /dev/vdb /mnt || say "FAIL test disk"

# The state: every regular file under the watched folders, with its hash; temporaries by name.
report() {
  local dir f
  for dir in etc calibration last-good; do
    [ -d "$cfg/$dir" ] || continue
    for f in "$cfg/$dir"/* "$cfg/$dir"/.*; do
      [ -f "$f" ] || continue
      case ${f##*/} in
        .*) say "temp ${f#"$cfg"/} $(stat -c %s "$f")" ;;
        *) say "file ${f#"$cfg"/} $(sha256sum < "$f" | cut -c1-64) $(stat -c %s "$f")" ;;
      esac
    done
  done
  say "state-done uptime=$(uptime_s)"
}

# A timed wait without forking (sleep would fork under TCG every 20 ms).
mkfifo /tmp/never
exec 4<> /tmp/never
nap() { read -r -t "$1" -u 4 _; }

# Prints the folder's listing whenever it changes, while process $1 lives.
watch_folder() {
  local pid=$1 dir=$2 now last=""
  shopt -s nullglob dotglob
  while kill -0 "$pid" 2> /dev/null; do
    now=$(cd "$dir" 2> /dev/null && echo *)
    if [ "$now" != "$last" ]; then say "ev $(uptime_s) $now"; last=$now; fi
    nap 0.02
  done
  shopt -u nullglob dotglob
}

finish() {
  local pid=$1 rc
  wait "$pid"
  rc=$?
  say "exit rc=$rc $(uptime_s)"
  tail -n 5 /tmp/run.log | while read -r line; do say "log $line"; done
  sync
}

run_calibrate() {
  mogao-calibrate --site /mnt/site.toml --images /mnt/captures --scale "$(cat /mnt/scale)" \
    --camera-transfer linear --no-bow --out "$cfg/calibration" --install "$cfg/etc/screen.mpcdi" > /tmp/run.log 2>&1 &
  local pid=$!
  while [ ! -e "$cfg/calibration/calibration.models.json" ] && kill -0 "$pid" 2> /dev/null; do nap 0.01; done
  kill -STOP "$pid"
  say "frozen $(uptime_s)"
  read -r _ <&3
  kill -CONT "$pid"
  say "go $(uptime_s)"
  watch_folder "$pid" "$cfg/etc"
  finish "$pid"
}

run_config() {
  say "frozen $(uptime_s)"
  read -r _ <&3
  say "go $(uptime_s)"
  MOGAO_LAST_GOOD_DIR=$cfg/last-good mogao-kiosk --config /etc/mogao/kiosk.toml --duration-s 2 > /tmp/run.log 2>&1 &
  local pid=$!
  watch_folder "$pid" "$cfg/last-good"
  finish "$pid"
}

report
# clocal: no modem lines on a virtual port (open would wait for carrier)
stty -F "$ctl" clocal -echo icanon 2> /dev/null
exec 3< "$ctl"
say "ready"
while read -r cmd <&3; do
  cmd=${cmd%$'\r'}
  case $cmd in
    calibrate) run_calibrate ;;
    config) run_config ;;
    report) report ;;
    sync) sync ;;
    *) say "unknown command '$cmd'" ;;
  esac
  say "ready"
done
say "FAIL control port closed"
while :; do nap 60; done
