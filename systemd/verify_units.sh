#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# systemd-analyze verify on every unit, with stand-in binaries so ExecStart resolves, and the
# offline security exposure score of each (recorded in docs/services.md).
set -uo pipefail
dir=$1
command -v systemd-analyze >/dev/null || { echo "SKIP: systemd-analyze not installed"; exit 77; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/root/usr/bin"
for b in mpirun mogao-farm mogao-farm-launch mogao-kiosk; do printf '#!/bin/sh\n' > "$work/root/usr/bin/$b"; chmod +x "$work/root/usr/bin/$b"; done
fail=0
for unit in "$dir"/*.service; do
  cp "$unit" "$work/"
  # Point ExecStart at the stand-ins (the units name /usr/bin paths of the installed system).
  sed -i "s|/usr/bin/|$work/root/usr/bin/|g" "$work/$(basename "$unit")"
  if out=$(systemd-analyze verify "$work/$(basename "$unit")" 2>&1) && [ -z "$out" ]; then
    echo "ok: verify $(basename "$unit")"
  else
    echo "FAIL: verify $(basename "$unit")"; echo "$out"; fail=1
  fi
  score=$(systemd-analyze security --offline=true "$work/$(basename "$unit")" 2>/dev/null | tail -1)
  echo "security $(basename "$unit"): $score"
done
exit $fail
