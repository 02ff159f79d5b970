#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# systemd-analyze verify on every unit, with stand-in binaries so ExecStart resolves, and the
# offline security exposure score of each (recorded in docs/services.md).
#   verify_units.sh SRC_DIR [INSTALLED_DIR BINDIR]
# INSTALLED_DIR: the copies CMake installs, whose programs are in BINDIR (CMAKE_INSTALL_FULL_BINDIR).
set -uo pipefail
dir=$1 installed=${2:-} bindir=${3:-/usr/bin}
command -v systemd-analyze >/dev/null || { echo "SKIP: systemd-analyze not installed"; exit 77; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/root/usr/bin"
mkdir -p "$work/root/usr/lib/mogao"
for b in bin/mpirun bin/mogao-farm bin/mogao-farm-launch bin/mogao-kiosk lib/mogao/mogao-service \
    lib/mogao/mogao-update; do
  printf '#!/bin/sh\n' > "$work/root/usr/$b"; chmod +x "$work/root/usr/$b"
done
fail=0
for unit in "$dir"/*.service ${installed:+"$installed"/*.service}; do
  cp "$unit" "$work/"
  # Point ExecStart at the stand-ins (the units name /usr/bin paths of the installed system; the
  # installed copies their BINDIR's).
  from=/usr/bin/ libexec=/usr/lib/mogao/
  [[ "$unit" == "$installed"/* ]] && from=$bindir/ libexec=${bindir%/bin}/lib/mogao/
  sed -i -e "s|$from|$work/root/usr/bin/|g" -e "s|$libexec|$work/root/usr/lib/mogao/|g" "$work/$(basename "$unit")"
  if out=$(systemd-analyze verify "$work/$(basename "$unit")" 2>&1) && [ -z "$out" ]; then
    echo "ok: verify $unit"
  else
    echo "FAIL: verify $(basename "$unit")"; echo "$out"; fail=1
  fi
  score=$(systemd-analyze security --offline=true "$work/$(basename "$unit")" 2>/dev/null | tail -1)
  echo "security $(basename "$unit"): $score"
done
exit $fail
