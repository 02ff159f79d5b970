#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# farm_package_test.sh REPO DEB_DIR APT_CACHE
#
# The mogao-farm package on a stock Debian 12 root, as a museum's technician installs it
# (docs/packaging.md): mmdebstrap makes a fresh bookworm root (apt, systemd), `apt install
# ./mogao-farm_*.deb` installs it with its dependencies from Debian, then the checks:
#   * the mogao-farm user (971, home /var/lib/mogao-farm) and its folders exist, /etc/mogao/farm.env
#     and farm-hosts are conffiles, the unit is enabled and the farm not started (no TLS files yet);
#   * the README's three `mogao-farm pki` commands (init-ca, issue-farm, export-farm);
#   * the mogao-appliance package (the link client), Mesa's EGL and Debian's prometheus-node-exporter
#     installed beside it, the farm's --metrics-file in the exporter's textfile folder;
#   * the farm starts: booted under systemd-nspawn where this machine allows it (`systemctl enable
#     --now mogao-farm`, active = READY, listening on 7443); otherwise (no systemd on the host, a
#     cgroup v1 container...) the unit's own start as systemd would run it, in the root (chroot):
#     the ExecStartPre as root, then ExecStart as the mogao-farm user with farm.env's variables, a
#     notification socket for READY=1, and the listening port. The log says which ran;
#   * it serves frames: the kiosk (headless outputs) with an appliance certificate of the same CA
#     shows 10 of the farm's frames, and the farm's metrics file, written as the mogao-farm user
#     into node_exporter's folder (the package's tmpfiles ACL), counts them.
#
# DEB_DIR: where .ci/package builds this tree's packages first (MOGAO_FARM_DEB=FILE: test that
# package instead, no build).
# APT_CACHE: folder of .deb files shared with the image builds (image/lib/debian.sh): packages
# are taken from it and new downloads added to it, so that Debian's mirror serves each once.
# Opt-in like the QEMU image tests: runs only with MOGAO_IMAGE_TESTS=1 (root, Debian's mirrors,
# a few minutes), exit 77 otherwise or when a tool is missing.
set -euo pipefail
repo=$1 deb_dir=$2 cache=$3
log() { echo "[farm_package_test] $*"; }
fail() { echo "[farm_package_test] FAIL: $*" >&2; exit 1; }
skip() { echo "SKIP: $*"; exit 77; }

[[ "${MOGAO_IMAGE_TESTS:-0}" == 1 ]] || skip "MOGAO_IMAGE_TESTS=1 not set (root, Debian's mirrors, a few minutes)"
[[ $(id -u) == 0 ]] || skip "needs root (mmdebstrap, chroot)"
for tool in mmdebstrap chroot unshare dpkg-deb python3; do
  command -v "$tool" > /dev/null || skip "missing tool '$tool'"
done
t0=$(date +%s)
source "$repo/image/lib/common.sh"
source "$repo/image/lib/debian.sh"
# .ci/package runs with the caller's locale, not this script's LC_ALL: ccache hashes the locale
# variables, and the main build compiled with the caller's.
package_env=(env -u LC_ALL)
[[ -n "${LC_ALL:-}" ]] && package_env=(env "LC_ALL=$LC_ALL")
export SOURCE_DATE_EPOCH=${SOURCE_DATE_EPOCH:-$(date +%s)} LC_ALL=C.UTF-8
work=$(mktemp -d /tmp/mogao-farm-package.XXXXXX)
root="$work/root"
pid_nspawn=""
cleanup() {
  [[ -n "$pid_nspawn" ]] && kill "$pid_nspawn" 2> /dev/null && wait "$pid_nspawn" 2> /dev/null
  rm -rf "$work"
}
trap cleanup EXIT

# ---- a stock Debian 12 root with apt and systemd (its lists kept, so that apt can install) -------
t1=$(date +%s)
img_mmdebstrap "$root" "$work/mmdebstrap.log" "$cache" "apt,systemd,systemd-sysv,dbus,iproute2" \
  --skip=cleanup/apt/lists --customize-hook='cp /etc/resolv.conf "$1/etc/resolv.conf"'
log "root: mmdebstrap bookworm in $(($(date +%s) - t1)) s"

# ---- the package: this tree's, built now, or MOGAO_FARM_DEB ---------------------------------------
deb=${MOGAO_FARM_DEB:-}
if [[ -z "$deb" ]]; then
  log "bash .ci/package $deb_dir (the packages of this tree; MOGAO_FARM_DEB=FILE tests that one instead)"
  rm -f "$deb_dir"/*.deb
  "${package_env[@]}" bash "$repo/.ci/package" "$deb_dir" > "$deb_dir.log" 2>&1 \
    || { tail -n 30 "$deb_dir.log"; fail "bash .ci/package $deb_dir failed"; }
  deb=$(ls "$deb_dir"/mogao-farm_*.deb)
fi
[[ -f "$deb" ]] || fail "no package $deb"
log "package: $deb"


# in_root CMD...: CMD in the root with /proc, /sys and /dev, in a mount namespace of its own.
in_root() {
  unshare --mount --propagation private -- /bin/sh -c '
    r=$1; shift
    mount -t proc proc "$r/proc" && mount -t sysfs sys "$r/sys" && mount --rbind /dev "$r/dev" || exit 1
    exec chroot "$r" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin LC_ALL=C.UTF-8 HOME=/root "$@"' sh "$root" "$@"
}

# ---- apt install ./mogao-farm_*.deb: its dependencies from Debian (the shared cache first) --------
t2=$(date +%s)
cp "$deb" "$root/tmp/"
find "$cache" -maxdepth 1 -name '*.deb' -exec cp -n -t "$root/var/cache/apt/archives/" {} + 2> /dev/null || true
in_root env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "/tmp/$(basename "$deb")" \
  > "$work/apt.log" 2>&1 || { tail -n 40 "$work/apt.log"; fail "apt install ./$(basename "$deb") failed"; }
find "$root/var/cache/apt/archives" -maxdepth 1 -name '*.deb' -exec cp -n -t "$cache/" {} + 2> /dev/null || true
log "apt install ./$(basename "$deb"): $(($(date +%s) - t2)) s," \
  "$(grep -c '^Setting up' "$work/apt.log") packages set up"

# ---- what the package installed and set up ---------------------------------------------------------
# root_stat PATH...: "PATH USER:GROUP MODE" with the root's user and group names (the host running
# this test has no mogao-farm user: stat's %U prints 971 there), PATH without the root's prefix.
root_stat() {
  local p uid gid mode user group
  for p in "$@"; do
    read -r uid gid mode < <(stat -c '%u %g %a' "$p")
    user=$(awk -F: -v id="$uid" '$3 == id { print $1; exit }' "$root/etc/passwd")
    group=$(awk -F: -v id="$gid" '$3 == id { print $1; exit }' "$root/etc/group")
    echo "${p#"$root"} $user:$group $mode"
  done
}
grep -q '^mogao-farm:x:971:971:[^:]*:/var/lib/mogao-farm:/bin/sh$' "$root/etc/passwd" \
  || fail "no mogao-farm user 971:971 with home /var/lib/mogao-farm: $(grep mogao "$root/etc/passwd" || echo none)"
[[ "$(root_stat "$root/var/lib/mogao-farm/.ssh")" == *" mogao-farm:mogao-farm 700" ]] \
  || fail "$(root_stat "$root/var/lib/mogao-farm/.ssh"), not mogao-farm:mogao-farm 0700"
conffiles=$(in_root dpkg-query -W -f='${Conffiles}' mogao-farm)
for f in /etc/mogao/farm.env /etc/mogao/farm-hosts; do
  grep -q " $f " <<<"$conffiles " || fail "$f is not a conffile of mogao-farm: $conffiles"
done
[[ -L "$root/etc/systemd/system/multi-user.target.wants/mogao-farm.service" ]] || fail "mogao-farm.service not enabled"
[[ ! -e "$root/etc/mogao/pki" ]] || fail "/etc/mogao/pki exists before the PKI commands"
in_root mogao-farm --version | grep -q '^mogao-farm ' || fail "mogao-farm --version"
log "ok: user mogao-farm, conffiles farm.env and farm-hosts, unit enabled, no TLS files yet"

# ---- what a museum adds beside the farm: Debian's node exporter (the farm's Recommends; its textfile
# folder, where the farm's metrics go) and a link client, the mogao-appliance package's kiosk with
# Mesa's software EGL. The exporter's own service stays off (the test reads its folder) -------------
appliance_deb=${MOGAO_APPLIANCE_DEB:-$(ls "$(dirname "$deb")"/mogao-appliance_*.deb 2> /dev/null | head -n1)}
[[ -f "$appliance_deb" ]] || fail "no mogao-appliance package beside $deb (MOGAO_APPLIANCE_DEB=FILE)"
t3=$(date +%s)
cp "$appliance_deb" "$root/tmp/"
in_root env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends \
  "/tmp/$(basename "$appliance_deb")" libegl-mesa0 libgl1-mesa-dri prometheus-node-exporter \
  > "$work/apt-client.log" 2>&1 \
  || { tail -n 40 "$work/apt-client.log"; fail "apt install of the client and node exporter failed"; }
find "$root/var/cache/apt/archives" -maxdepth 1 -name '*.deb' -exec cp -n -t "$cache/" {} + 2> /dev/null || true
in_root systemctl disable prometheus-node-exporter > /dev/null 2>&1 || true
textfile_dir=/var/lib/prometheus/node-exporter
[[ -d "$root$textfile_dir" ]] || fail "prometheus-node-exporter made no $textfile_dir"
log "apt install ./$(basename "$appliance_deb") (the client), Mesa EGL, prometheus-node-exporter:" \
  "$(($(date +%s) - t3)) s;" \
  "$(root_stat "$root$textfile_dir")"
sed -i "s|^MOGAO_FARM_ARGS=.*|MOGAO_FARM_ARGS=--metrics-file $textfile_dir/mogao-farm.prom|" "$root/etc/mogao/farm.env"

# ---- the README's PKI commands, then the farm starts: under systemd where the root can boot, else
# the unit's start by hand --------------------------------------------------------------------------
# pki_commands RUNNER...: init-ca, issue-farm, export-farm, each run through RUNNER.
pki_commands() {
  "$@" mogao-farm pki init-ca --dir /root/mogao-ca > "$work/pki.log" 2>&1 \
    || { cat "$work/pki.log"; fail "pki init-ca"; }
  "$@" mogao-farm pki issue-farm --dir /root/mogao-ca --name farm-1 --san ::1 >> "$work/pki.log" 2>&1 \
    || { cat "$work/pki.log"; fail "pki issue-farm"; }
  "$@" mogao-farm pki export-farm --dir /root/mogao-ca --name farm-1 --to /etc/mogao/pki >> "$work/pki.log" 2>&1 \
    || { cat "$work/pki.log"; fail "pki export-farm"; }
  log "ok: pki init-ca, issue-farm, export-farm: $(ls "$root/etc/mogao/pki" | tr '\n' ' ')"
}
source "$(dirname "$0")/farm_package_start.sh"
sed -i "s/^MOGAO_LISTEN=.*/MOGAO_LISTEN=[::]:$farm_port/" "$root/etc/mogao/farm.env"
if boot_under_systemd; then
  pki_commands in_container
  start_under_systemd
  serve_frames in_container
  configuration_error_under_systemd
  stop_container
else
  log "systemd cannot boot here ($nspawn_reason):" \
    "the unit's ExecStartPre and ExecStart as systemd runs them, in a chroot"
  pki_commands in_root
  start_as_the_unit_does
  check_served_frames
fi
log "PASS in $(($(date +%s) - t0)) s"
