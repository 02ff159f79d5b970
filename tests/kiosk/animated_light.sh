#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# An animated light, end to end: the farm (3 MPI ranks) serves a copy of the test room whose sun,
# point and area lights switch between full power and a tenth every STEP_S seconds of scene time
# (scene file "animation", docs/scene-format.md), to a headless mogao-kiosk that stands still (a
# one-pose path), over [::1] with mutual TLS. The scene time is stamped by the admin and carried to
# the render ranks with each view; a light that changes empties the ranks' radiance cache and
# restarts the admin's still view (docs/renderer.md). Checks on the content frames the kiosk
# received (every one dumped, decoded):
#   * the frames follow the light: the brightest frame at least MIN_RATIO x the darkest, and at
#     least MIN_CHANGES changes between bright and dark frames (the ranks see the time);
#   * no frame mixes the two lightings: every frame within MIX_TOL of its own group's median (a still
#     view that kept the old light's samples would fade from one level to the other);
#   * no frame rejected, request ids strictly increasing.
#
# usage: animated_light.sh FARM KIOSK IMAGE_TOOL MPIEXEC SOURCE_DIR WORK_DIR
farm=$1 kiosk=$2 tool=$3 MPIEXEC=$4 src=$5 work=$6
source "$src/tests/kiosk/kiosk_e2e_common.sh"

STEP_S=2.5       # seconds of scene time per lighting step
RUN_S=14         # the kiosk's run: five or six steps
MIN_RATIO=2.0    # bright / dark frame mean (the lights' power drops to 0.1; the environment stays)
MIN_CHANGES=3
MIX_TOL=0.12     # |frame mean / its group's median - 1|

trap cleanup EXIT
rm -rf "$work"
mkdir -p "$work"
python3 - "$src/scenes/test-room.json" "$work/flicker-room.json" "$STEP_S" <<'PY'
import json, sys
scene = json.load(open(sys.argv[1]))
for light in scene["lights"]:
    if light["type"] != "environment":
        light["animation"] = {"step_s": float(sys.argv[3]), "scale": [1.0, 0.1]}
json.dump(scene, open(sys.argv[2], "w"), indent=1)
PY
cat > "$work/still.json" <<'JSON'
{"keyframes": [{"position": [0.0, 0.0, 4.0], "yaw_deg": 0, "pitch_deg": 0},
               {"position": [0.0, 0.0, 4.0], "yaw_deg": 0, "pitch_deg": 0}]}
JSON
FARM_SCENE="$work/flicker-room.json"
# As a gallery is served: progressive still views, the radiance cache and temporal accumulation on.
FARM_BUDGET_ARGS=(--frame-budget-s 0 --quality interactive)
port=$((20000 + ($$ + 5171) % 20000))
endpoint="[::1]:$port"
make_pki "$work/pki" "::1"
write_config "$work/kiosk.toml" "$endpoint" "$work/pki" "$work/png" 1000000 "navigation.path=\"$work/still.json\""
start_farm "$work/farm.log" "$endpoint"
log "farm up at $endpoint serving $FARM_SCENE (lights step every $STEP_S s)"

timeout 120 "$kiosk" --config "$work/kiosk.toml" --frames 1000000 --duration-s "$RUN_S" \
  --dump-content "$work/content" --dump-every 1 --stats "$work/stats.json" >"$work/kiosk.log" 2>&1
rc=$?
stop_farm TERM
(( rc == 0 )) || { cat "$work/kiosk.log"; fail "mogao-kiosk exited with $rc"; }
check_stats "$work/stats.json" 10 || fail "see above"

python3 - "$work/content" "$MIN_RATIO" "$MIN_CHANGES" "$MIX_TOL" <<'PY' || fail "see above"
import glob, json, os, re, statistics, sys
folder, min_ratio, min_changes, tol = sys.argv[1], float(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4])

def ppm_mean(path):
    data = open(path, "rb").read()
    m = re.match(rb"P6\s+(\d+)\s+(\d+)\s+(\d+)\s", data)
    assert m, f"{path}: not a binary PPM"
    pixels = data[m.end():]
    return sum(pixels) / len(pixels)

frames = sorted(glob.glob(os.path.join(folder, "content-req*.ppm")),
                key=lambda p: int(re.search(r"req(\d+)", p).group(1)))
means = [ppm_mean(p) for p in frames]
if len(means) < 10:
    sys.exit(f"FAIL: {len(means)} content frames dumped, at least 10 expected")
hi, lo = max(means), min(means)
print(f"{len(means)} frames; frame means {lo:.1f} .. {hi:.1f} (8-bit codes)")
print("means in order:", " ".join(f"{m:.0f}" for m in means))
ok = True
if not lo > 0 or hi / lo < min_ratio:
    print(f"FAIL: brightest / darkest frame {hi / max(lo, 1e-9):.2f}, at least {min_ratio} expected: "
          "the frames do not follow the light"); ok = False
cut = (hi + lo) / 2
bright = [m > cut for m in means]
changes = sum(a != b for a, b in zip(bright, bright[1:]))
print(f"{changes} changes between bright and dark frames")
if changes < min_changes:
    print(f"FAIL: {changes} changes, at least {min_changes} expected"); ok = False
for group in (True, False):
    level = statistics.median([m for m, b in zip(means, bright) if b == group] or [1])
    mixed = [(os.path.basename(p), m) for p, m, b in zip(frames, means, bright)
             if b == group and abs(m / level - 1) > tol]
    if mixed:
        print(f"FAIL: frames between the two lightings ({'bright' if group else 'dark'} median {level:.1f}): "
              f"{mixed[:5]}"); ok = False
sys.exit(0 if ok else 1)
PY
log "PASS"
