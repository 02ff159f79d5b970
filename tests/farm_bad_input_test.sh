#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Bad input to a multi-rank farm ends quickly with a clear message and exit code != 0 — no hang
# (the CTest TIMEOUT catches a hang), no crash.
set -uo pipefail
farm=$1 MPIEXEC=$2 work=$3
source "$(dirname "$0")/mpi_env.sh"
rm -rf "$work" && mkdir -p "$work"
fail=0
expect_failure() {  # name, expected fragment, args...
  local name=$1 fragment=$2; shift 2
  if timeout 120 "$MPIEXEC" --oversubscribe -n 3 "$farm" "$@" > "$work/$name.log" 2>&1; then
    echo "FAIL: $name: exit code 0"; fail=1; return
  fi
  if ! grep -q -- "$fragment" "$work/$name.log"; then
    echo "FAIL: $name: message lacks '$fragment':"; cat "$work/$name.log"; fail=1; return
  fi
  echo "ok: $name: $(grep -m1 -- "$fragment" "$work/$name.log")"
}
printf '{ "meshes": { "m": { "file": "missing.obj" } }, "objects": [ { "mesh": "m" } ] }' > "$work/missing-mesh.json"
expect_failure missing-mesh "missing.obj" render --scene "$work/missing-mesh.json" --out "$work/o1" --frames 1
printf '{ "meshes": { "m": { "procedural": "box", "size": [1, 1, 1] } }, "objects": [ { "mesh": "m", "transform": { "scale": -2 } } ] }' > "$work/bad-scale.json"
expect_failure bad-scale "objects\[0\].transform.scale" render --scene "$work/bad-scale.json" --out "$work/o2" --frames 1
printf 'ply\nformat binary_little_endian 1.0\nelement vertex 100\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n' > "$work/truncated.ply"
printf '{ "meshes": { "m": { "file": "truncated.ply" } }, "objects": [ { "mesh": "m" } ] }' > "$work/truncated.json"
expect_failure truncated-ply "truncated.ply" render --scene "$work/truncated.json" --out "$work/o3" --frames 1
printf '{ "meshes": { "m": { "procedural": "box", "size": [1, 1, 1] } }, "objects": [ { "mesh": "m" } ] }' > "$work/ok.json"
expect_failure bad-path "nonexistent-path.json" render --scene "$work/ok.json" --out "$work/o4" --frames 2 --path "$work/nonexistent-path.json"
expect_failure bad-spp "spp" render --scene "$work/ok.json" --out "$work/o5" --frames 1 --spp 0
[ $fail -eq 0 ] && echo "PASS: bad input fails cleanly"
exit $fail
