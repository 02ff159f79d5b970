#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# A frame rendered by N ranks equals the frame rendered by one process, pixel for pixel, for the
# given balancer (the per-pixel RNG depends only on pixel and seed, never on the rect or rank).
set -euo pipefail
farm=$1 MPIEXEC=$2 scene=$3 balancer=$4 work=$5
source "$(dirname "$0")/mpi_env.sh"
rm -rf "$work" && mkdir -p "$work"
# On any failure show what the ranks said.
trap 'status=$?; [ $status -ne 0 ] && for l in "$work"/*.log; do echo "== $l"; cat "$l"; done; exit $status' EXIT
common=(render --scene "$scene" --frames 3 --path orbit --width 160 --height 96 --spp 2 --ao 2 --bounces 1
        --save-raw --contact-sheet 0 --balance "$balancer")
mpirun_n 1 "$farm" "${common[@]}" --out "$work/one" 2> "$work/one.log"
mpirun_n 4 "$farm" "${common[@]}" --out "$work/four" 2> "$work/four.log"
fail=0
for f in "$work"/one/frame-*.ppm; do
  other="$work/four/$(basename "$f")"
  if ! cmp -s "$f" "$other"; then echo "FAIL: $(basename "$f") differs between 1 and 4 ranks ($balancer)"; fail=1; fi
done
n=$(ls "$work"/one/frame-*.ppm | wc -l)
[ "$n" -eq 3 ] || { echo "FAIL: expected 3 frames, got $n"; fail=1; }
for f in stats.json tile-costs.json frame-0000.jpg; do
  [ -s "$work/four/$f" ] || { echo "FAIL: $f missing"; fail=1; }
done
# The 4-rank run used 3 render ranks: every frame has three rank times. Render threads (automatic,
# renderfarm/farm/render_threads.h): this host's CPUs shared among its render ranks, at least one.
python3 - "$work/four/stats.json" "$work/one/stats.json" <<'PY' || fail=1
import json, os, sys
s = json.load(open(sys.argv[1]))
cpus = len(os.sched_getaffinity(0))
assert s["run"]["render_ranks"] == 3, s["run"]
assert s["run"]["threads_per_rank"] == max(1, cpus // 3), (s["run"], cpus)
one = json.load(open(sys.argv[2]))["run"]
assert one["threads_per_rank"] == cpus, (one, cpus)
for f in s["frames"]:
    assert len(f["rank_render_seconds"]) == 3, f
    assert 0 < f["balance_efficiency"] <= 1, f
    assert f["rays"] > 160 * 96, f
    assert f["jpeg_bytes"] > 0, f
print("stats ok:", len(s["frames"]), "frames, mean efficiency", round(s["summary"]["mean_balance_efficiency"], 3))
PY
[ $fail -eq 0 ] && echo "PASS: 1-rank and 4-rank frames identical ($balancer)"
exit $fail
