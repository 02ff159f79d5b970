#!/usr/bin/env bash
# Load-balance efficiency (mean rank time / max rank time) of PBT vs equal split vs round-robin on
# the grotto's walk, with real MPI ranks on this machine, then simulated for N = 4, 8, 16 render
# ranks from the per-tile costs the PBT run measured. Prints markdown; ratios are from this run.
#   bash bench/balance_bench.sh [build dir] [frames] [width] [height] [ranks]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build} frames=${2:-30} width=${3:-960} height=${4:-540} ranks=${5:-3}
scans=${MOGAO_SCANS_DIR:-$(pwd)/../shared/data/scans}
[ -d "$scans" ] || { echo "SKIP: real scans not found at $scans"; exit 77; }
source tests/mpi_env.sh
MPIEXEC=mpirun
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "## Load balance on the grotto walk: $frames frames ${width}x${height}, $ranks MPI ranks ($((ranks - 1)) render ranks), 1 thread each"
echo
echo "| balancer | mean efficiency (frames 1..) | min efficiency | mean frame s | mean render phase s |"
echo "|---|--:|--:|--:|--:|"
for b in pbt equal roundrobin; do
  mpirun_n "$ranks" "$build/renderfarm/farm/mogao-farm" render --scene scenes/grotto.json --scans "$scans" \
    --frames "$frames" --width "$width" --height "$height" --balance "$b" --contact-sheet 0 --out "$work/$b" 2> "$work/$b.log"
  python3 - "$work/$b/stats.json" "$b" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
f = s["frames"][1:] or s["frames"]
eff = [x["balance_efficiency"] for x in f]
print(f"| {sys.argv[2]} | {sum(eff)/len(eff):.3f} | {min(eff):.3f} | "
      f"{sum(x['frame_seconds'] for x in f)/len(f):.3f} | {sum(x['render_phase_seconds'] for x in f)/len(f):.3f} |")
PY
done
python3 - "$work" <<'PY'
import json, sys
w = sys.argv[1]
def mean_eff(b):
    f = json.load(open(f"{w}/{b}/stats.json"))["frames"][1:]
    return sum(x["balance_efficiency"] for x in f) / len(f)
def mean_phase(b):
    f = json.load(open(f"{w}/{b}/stats.json"))["frames"][1:]
    return sum(x["render_phase_seconds"] for x in f) / len(f)
print()
print(f"Ratios, same run: efficiency pbt/equal = {mean_eff('pbt')/mean_eff('equal'):.3f}, "
      f"pbt/roundrobin = {mean_eff('pbt')/mean_eff('roundrobin'):.3f}; render phase time equal/pbt = "
      f"{mean_phase('equal')/mean_phase('pbt'):.3f}, roundrobin/pbt = {mean_phase('roundrobin')/mean_phase('pbt'):.3f}")
PY
echo
echo "## Simulated N = 4, 8, 16 render ranks from the measured per-tile costs (tile-costs.json of the pbt run)"
echo
"$build/bench/mogao_balance_sim" "$work/pbt/tile-costs.json" --ranks 4 8 16
