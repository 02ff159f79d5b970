#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Load-balance efficiency (mean rank time / max rank time) of PBT vs equal split vs round-robin on
# the grotto's walk, with real MPI ranks on this machine, then simulated for N = 4, 8, 16 render
# ranks from the per-tile costs the PBT run measured. Prints markdown; ratios are from this run.
#   bash bench/balance_bench.sh [build dir] [frames] [width] [height] [ranks] [--json FILE] [--scene FILE]
# --json FILE (anywhere on the line) also writes every figure as JSON (for bench/regenerate-docs);
# --scene FILE replaces scenes/grotto.json (scenes/test-room.json: a fast smoke run without the scans).
set -euo pipefail
cd "$(dirname "$0")/.."
json="" scene=scenes/grotto.json args=()
while [ $# -gt 0 ]; do
  case $1 in
    --json) json=$2; shift 2 ;;
    --scene) scene=$2; shift 2 ;;
    *) args+=("$1"); shift ;;
  esac
done
set -- "${args[@]+"${args[@]}"}"
build=${1:-build} frames=${2:-30} width=${3:-960} height=${4:-540} ranks=${5:-3}
scans=${MOGAO_SCANS_DIR:-$(pwd)/../shared/data/scans}
if grep -q '{scans}' "$scene" && [ ! -d "$scans" ]; then echo "SKIP: real scans not found at $scans"; exit 77; fi
source tests/mpi_env.sh
MPIEXEC=mpirun
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for b in pbt equal roundrobin; do
  mpirun_n "$ranks" "$build/renderfarm/farm/mogao-farm" render --scene "$scene" --scans "$scans" \
    --frames "$frames" --width "$width" --height "$height" --balance "$b" --contact-sheet 0 --out "$work/$b" \
    2> "$work/$b.log" \
    || { cat "$work/$b.log" >&2; exit 1; }
done
"$build/bench/mogao_balance_sim" "$work/pbt/tile-costs.json" --ranks 4 8 16 --json "$work/sim.json" > /dev/null
python3 - "$work" "$frames" "$width" "$height" "$ranks" "$json" "$scene" <<'PY'
import json, os, sys
w, frames, width, height, ranks, out, scene = sys.argv[1], *map(int, sys.argv[2:6]), sys.argv[6], sys.argv[7]
real = []
for b in ("pbt", "equal", "roundrobin"):
    f = json.load(open(f"{w}/{b}/stats.json"))["frames"]
    f = f[1:] or f  # frame 0 uses the uniform prediction
    eff = [x["balance_efficiency"] for x in f]
    real.append({"balancer": b, "mean_efficiency": sum(eff) / len(eff), "min_efficiency": min(eff),
                 "mean_frame_seconds": sum(x["frame_seconds"] for x in f) / len(f),
                 "mean_render_phase_seconds": sum(x["render_phase_seconds"] for x in f) / len(f)})
by = {r["balancer"]: r for r in real}
render_phase = {b: by[b]["mean_render_phase_seconds"] for b in ("pbt", "equal", "roundrobin")}
ratios = {"efficiency_pbt_over_equal": by["pbt"]["mean_efficiency"] / by["equal"]["mean_efficiency"],
          "efficiency_pbt_over_roundrobin": by["pbt"]["mean_efficiency"] / by["roundrobin"]["mean_efficiency"],
          "render_phase_equal_over_pbt": render_phase["equal"] / render_phase["pbt"],
          "render_phase_roundrobin_over_pbt": render_phase["roundrobin"] / render_phase["pbt"]}
sim = json.load(open(f"{w}/sim.json"))
sim["input"]["file"] = "tile-costs.json of the pbt run"
result = {"bench": "balance", "scene": os.path.basename(scene), "frames": frames, "width": width, "height": height,
          "mpi_ranks": ranks, "render_ranks": ranks - 1, "threads_per_rank": 1, "real": real, "ratios": ratios,
          "simulated": sim}
if out:
    with open(out, "w") as fh:
        json.dump(result, fh, indent=1)
        fh.write("\n")
import importlib.machinery, importlib.util
loader = importlib.machinery.SourceFileLoader("summarize", "bench/summarize")
summarize = importlib.util.module_from_spec(importlib.util.spec_from_loader("summarize", loader))
loader.exec_module(summarize)
print(summarize.balance_tables(result))
PY
