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
  timeout 120 "$MPIEXEC" --oversubscribe -n 3 "$farm" "$@" > "$work/$name.log" 2>&1
  local rc=$?
  [ $rc -eq 0 ] && { echo "FAIL: $name: exit code 0"; fail=1; return; }
  # A rank that gave up alone leaves the others waiting: the message is there, the job never ends.
  [ $rc -eq 124 ] && { echo "FAIL: $name: the job did not end within 120 s (a rank waits for one that gave up)";
      fail=1; return; }
  if ! grep -q -- "$fragment" "$work/$name.log"; then
    echo "FAIL: $name: message lacks '$fragment':"; cat "$work/$name.log"; fail=1; return
  fi
  echo "ok: $name: $(grep -m1 -- "$fragment" "$work/$name.log")"
}
printf '{ "meshes": { "m": { "file": "missing.obj" } }, "objects": [ { "mesh": "m" } ] }' > "$work/missing-mesh.json"
expect_failure missing-mesh "missing.obj" render --scene "$work/missing-mesh.json" --out "$work/o1" --frames 1
printf '{ "meshes": { "m": { "procedural": "box", "size": [1, 1, 1] } }, %s }' \
  '"objects": [ { "mesh": "m", "transform": { "scale": -2 } } ]' > "$work/bad-scale.json"
expect_failure bad-scale "objects\[0\].transform.scale" render --scene "$work/bad-scale.json" --out \
    "$work/o2" --frames 1
printf '%s\n' ply 'format binary_little_endian 1.0' 'element vertex 100' 'property float x' 'property float y' \
  'property float z' 'element face 1' 'property list uchar int vertex_indices' end_header > "$work/truncated.ply"
printf '{ "meshes": { "m": { "file": "truncated.ply" } }, "objects": [ { "mesh": "m" } ] }' > "$work/truncated.json"
expect_failure truncated-ply "truncated.ply" render --scene "$work/truncated.json" --out "$work/o3" --frames 1
printf '{ "meshes": { "m": { "procedural": "box", "size": [1, 1, 1] } }, "objects": [ { "mesh": "m" } ] }' > \
    "$work/ok.json"
expect_failure bad-path "nonexistent-path.json" render --scene "$work/ok.json" --out "$work/o4" --frames 2 \
    --path "$work/nonexistent-path.json"
expect_failure bad-spp "spp" render --scene "$work/ok.json" --out "$work/o5" --frames 1 --spp 0
expect_failure bad-preset "unknown preset 'fast' (known: interactive, balanced, exhibit)" \
  render --scene "$work/ok.json" --out "$work/o6" --frames 1 --quality fast
# A preset sets every knob not given explicitly; an explicit flag wins.
if timeout 120 "$MPIEXEC" --oversubscribe -n 2 "$farm" render --scene "$work/ok.json" --out "$work/o7" --frames 1 \
    --width 32 --height 18 --quality exhibit --spp 3 > "$work/preset.log" 2>&1; then
  run=$(python3 -c "import json,sys; r=json.load(open(sys.argv[1]))['run']; \
print(r['spp'], r['max_bounces'], r['ao_samples'], r['jpeg_quality'])" "$work/o7/stats.json")
  if [ "$run" = "3 4 0 95" ]; then echo "ok: --quality exhibit --spp 3 renders spp, bounces, AO, JPEG quality: $run"
  else echo "FAIL: --quality exhibit --spp 3 gave spp bounces AO JPEG = $run, expected 3 4 0 95" \
            "(common/quality_preset.cpp)"; fail=1; fi
else
  echo "FAIL: --quality exhibit did not render"; cat "$work/preset.log"; fail=1
fi
# serve: the link's TLS material lives on the admin host only (render hosts hold no key). A missing
# one on the admin ends every rank (exit 2, the path named); on render hosts it is not needed. The
# MPMD form gives rank 0 one --tls-dir and ranks 1-2 another, as two hosts' file systems would.
"$farm" pki init-ca --dir "$work/pki" > /dev/null && "$farm" pki issue-farm --dir "$work/pki" --name farm \
    --san ::1 > /dev/null \
  && "$farm" pki export-farm --dir "$work/pki" --name farm --to "$work/farm-tls" > /dev/null ||
  { echo "FAIL: pki"; fail=1; }
serve_args=(serve --scene "$work/ok.json" --listen "[::1]:0" --name farm --duration-s 2)
expect_failure admin-without-tls "$work/absent" "${serve_args[@]}" --tls-dir "$work/absent"
timeout 120 "$MPIEXEC" --oversubscribe -n 1 "$farm" "${serve_args[@]}" --tls-dir "$work/farm-tls" \
  : -n 2 "$farm" "${serve_args[@]}" --tls-dir "$work/absent" > "$work/render-without-tls.log" 2>&1
rc=$?
if [ $rc -eq 0 ]; then echo "ok: serve with the TLS files on the admin only: 3 ranks served and ended (exit 0)"
else echo "FAIL: serve with the TLS files on the admin only: exit $rc (124: a rank gave up alone, the others waited)"
  cat "$work/render-without-tls.log"; fail=1; fi
[ $fail -eq 0 ] && echo "PASS: bad input fails cleanly"
exit $fail
