#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The grotto with the real scans renders on 3 MPI ranks (small frames, few frames).
set -euo pipefail
farm=$1 MPIEXEC=$2 scene=$3 scans=$4 work=$5
if [ ! -d "$scans" ]; then echo "SKIP: real scans not found at $scans (../shared/data/scans)"; exit 77; fi
source "$(dirname "$0")/mpi_env.sh"
rm -rf "$work" && mkdir -p "$work"
mpirun_n 3 "$farm" render --scene "$scene" --scans "$scans" --frames 4 --width 320 --height 180 --out \
    "$work" 2> "$work/log"
cat "$work/log"
python3 - "$work/stats.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
tri = s["run"]["instanced_triangles"]
assert tri >= 500000, tri
meshes = {m["name"]: m["triangles"] for m in s["run"]["meshes"]}
assert meshes["igea"] == 268686, meshes
assert len(s["frames"]) == 4
print("PASS: grotto", tri, "triangles,", len(s["frames"]), "frames")
PY
