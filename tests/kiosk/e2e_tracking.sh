#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# End to end, tracking as the kiosk's navigation input: a hand-held tag sequence with known motion
# (`mogao-tag-sequence`: rest, turn the tag left 25 deg, back, push it 12 cm toward the
# camera, back, fast turn right 30 deg, back, tag out of view 11.0-11.6 s, rest; 12 s, 800x600)
# replayed as the camera of a headless kiosk ([navigation] source = "tracking",
# replay_end = "stop"), which streams from a 3-rank farm over [::1] with mutual TLS.
#
# Checks, from the kiosk's --pose-log (one submitted pose per display tick) and statistics:
#   * order of motion: the ticks in which the view moved, labelled L (yaw up: turned left),
#     F (moved along its forward direction f(yaw) = (-sin yaw, 0, -cos yaw)), R (yaw down) and
#     grouped into runs, read exactly L, F, R -- never backwards; two at once only in a transition
#     of at most 3 ticks between the two runs it mixes;
#   * sizes: L >= +30 deg (expected ~+90), F >= 0.3 m (~1.1 m), R <= -10 deg (~-40);
#   * no jump: between consecutive ticks |dyaw| <= 45 deg/s * dt and |deye| <= 1 m/s * dt (the
#     Navigator's caps) with dt the ticks' distance clamped to max_dt_s, plus 2%; eye height constant;
#   * tag lost: some ticks after the right turn are not tracking, and the view came to rest: the
#     poses of the last 0.5 s are identical, velocities 0;
#   * the kiosk stopped by itself at the end of the replay (exit 0), every frame tracked or skipped
#     behind a newer one (as a busy camera reader would), at least 60 tracked, the tag
#     seen in most, no sample dropped; farm frames were shown.
#
# usage: e2e_tracking.sh FARM KIOSK TAG_SEQUENCE MPIEXEC SOURCE_DIR WORK_DIR
farm=$1 kiosk=$2 tag_sequence=$3 MPIEXEC=$4 src=$5 work=$6
tool=true  # kiosk_e2e_common.sh's PNG checks are not used here
source "$src/tests/kiosk/kiosk_e2e_common.sh"

rm -rf "$work"
mkdir -p "$work"
"$tag_sequence" "$work/hand-sequence" >"$work/tag-sequence.log" 2>&1 \
  || { cat "$work/tag-sequence.log"; fail "mogao-tag-sequence"; }
[[ -f "$work/hand-sequence/camera.json" ]] || fail "mogao-tag-sequence wrote no camera.json"

port=$((20000 + ($$ + 4099) % 20000))
endpoint="[::1]:$port"
make_pki "$work/pki" "::1"
# 15 Hz display and requests (not 30): the farm's ranks and the outputs then leave the tracking
# thread a core's worth of time on a 2-core machine; navigation does not depend on the rate.
# A slow machine ticks and tracks less often (it has to pass on one core): max_dt_s = 0.5 lets the
# Navigator integrate display steps of up to 0.5 s instead of clamping them at 0.1 s (which loses
# motion), hold_s = 0.3 keeps the command across camera frames skipped behind newer ones (the tag
# is out of view for 0.6 s, longer than that), as kiosk/config/tour-tracking.overrides does.
# The scripted visitor's keys out, the tracking source in (the replay's camera.json is the intrinsics).
write_config "$work/kiosk.toml" "$endpoint" "$work/pki" "$work/png" 30 \
  'display.rate_hz=15' 'navigation.path=' 'navigation.path_frames=' 'navigation.source="tracking"' \
  'navigation.camera="replay:hand-sequence"' 'navigation.tag_size_m=0.10' 'navigation.tag_id=0' \
  'navigation.replay_end="stop"' 'navigation.control.max_dt_s=0.5' 'navigation.control.hold_s=0.3'
grep -q '^source = "tracking"' "$work/kiosk.toml" || fail "the tracking source is not in $work/kiosk.toml"
start_farm "$work/farm.log" "$endpoint"
log "farm up at $endpoint"

timeout 120 "$kiosk" --config "$work/kiosk.toml" --duration-s 90 --pose-log "$work/poses.jsonl" \
  --stats "$work/stats.json" >"$work/kiosk.log" 2>&1
rc=$?
stop_farm TERM
cat "$work/kiosk.log"
(( rc == 0 )) || fail "mogao-kiosk exited with $rc"
grep -q "stopping: the tracking replay ended" "$work/kiosk.log" ||
    fail "the kiosk did not stop at the end of the replay"
[[ -f "$work/poses.jsonl" ]] || fail "no pose log written"
[[ -f "$work/stats.json" ]] || fail "no statistics written"

python3 - "$work/poses.jsonl" "$work/stats.json" <<'PY' || fail "see above"
import json, math, sys

poses = [json.loads(line) for line in open(sys.argv[1])]
stats = json.load(open(sys.argv[2]))
nav = stats["navigation"]
ok = True

def bad(message):
    global ok
    print("FAIL:", message)
    ok = False

print(f"{len(poses)} poses; navigation stats: {json.dumps({k: nav[k] for k in nav if k != 'final_pose'})}")
print(f"final pose: {nav['final_pose']}; farm frames shown: {stats['frames_presented']}")
if nav["source"] != "tracking":
    bad(f"navigation source {nav['source']}")
# Every frame is tracked or, on a busy machine, skipped because a newer one was due (as a camera
# would drop it); most must be tracked for the motion checks below to mean anything.
if nav["frames_tracked"] + nav["frames_skipped"] != 360:
    bad(f"{nav['frames_tracked']} frames tracked + {nav['frames_skipped']} skipped, the sequence has 360")
if nav["frames_tracked"] < 60:
    bad(f"only {nav['frames_tracked']} of 360 frames tracked ({nav['frames_skipped']} skipped)")
if nav["tag_visible"] < 0.83 * nav["frames_tracked"]:
    bad(f"the tag was seen in {nav['tag_visible']} of {nav['frames_tracked']} tracked frames")
if nav["samples_dropped"] != 0:
    bad(f"{nav['samples_dropped']} samples dropped")
if stats["frames_presented"] < 5:
    bad(f"only {stats['frames_presented']} farm frames shown")
if len(poses) < 90:  # 180 at 15 Hz on an idle machine; a busy one ticks less often
    bad(f"only {len(poses)} poses for a 12 s replay at 15 Hz")

# No jumps between ticks: the Navigator's caps (45 deg/s, 1 m/s) times the step it integrates
# (the ticks' distance, clamped to max_dt_s = 0.5 s); eye height fixed.
MAX_DT_S, TURN_CAP, SPEED_CAP = 0.5, 45.0, 1.0
worst_yaw = worst_pos = 0.0
for a, b in zip(poses, poses[1:]):
    dt = min((b["t_ns"] - a["t_ns"]) * 1e-9, MAX_DT_S)
    dyaw = abs(b["yaw_deg"] - a["yaw_deg"])
    dpos = math.dist(a["eye"], b["eye"])
    worst_yaw, worst_pos = max(worst_yaw, dyaw / TURN_CAP / dt), max(worst_pos, dpos / SPEED_CAP / dt)
    if dyaw > 1.02 * TURN_CAP * dt + 1e-9 or dpos > 1.02 * SPEED_CAP * dt + 1e-9:
        bad(f"jump between ticks {a['tick']} and {b['tick']} ({dt:.3f} s): yaw {dyaw:.2f} deg, eye {dpos:.3f} m")
    if abs(b["eye"][1] - 1.6) > 1e-9:
        bad(f"tick {b['tick']}: eye height {b['eye'][1]}")
print(f"largest step between ticks as a share of the caps: turn {worst_yaw:.2f}, speed {worst_pos:.2f} (bound 1.02)")

# Label each tick's motion and group the labels into runs.
EPS_YAW, EPS_POS = 1e-6, 1e-6
runs = []  # [label, ticks, total yaw or distance, first tick]
for a, b in zip(poses, poses[1:]):
    dyaw = b["yaw_deg"] - a["yaw_deg"]
    d = [b["eye"][i] - a["eye"][i] for i in range(3)]
    dist = math.hypot(d[0], d[2])
    labels = []
    if dyaw > EPS_YAW:
        labels.append("L")
    elif dyaw < -EPS_YAW:
        labels.append("R")
    if dist > EPS_POS:
        mid = math.radians((a["yaw_deg"] + b["yaw_deg"]) / 2)
        along = -math.sin(mid) * d[0] - math.cos(mid) * d[2]
        labels.append("F" if along > 0.99 * dist else "B")
    if not labels:
        continue
    label = "+".join(labels)
    amount = dyaw if label in ("L", "R") else dist
    if runs and runs[-1][0] == label:
        runs[-1][1] += 1
        runs[-1][2] += amount
    else:
        runs.append([label, 1, amount, b["tick"]])
# A tick or two where one motion fades out as the next begins (e.g. "R+F" between the F and R
# runs: the filtered walk command still decaying when the turn starts, more likely when camera
# frames are skipped) is a transition, not a wrong order: set aside, at most 3 ticks each.
def is_transition(i):
    label, n = runs[i][0], runs[i][1]
    if "+" not in label or n > 3 or i == 0 or i + 1 == len(runs):
        return False
    parts = set(label.split("+"))
    before, after = runs[i - 1][0], runs[i + 1][0]
    return before != after and before in parts and after in parts
transitions = [r for i, r in enumerate(runs) if is_transition(i)]
runs = [r for i, r in enumerate(runs) if not is_transition(i)]
for label, n, _, first in transitions:
    print(f"  transition {label}: from tick {first}, {n} ticks (set aside)")
for label, n, amount, first in runs:
    unit = "deg" if label in ("L", "R") else "m"
    print(f"  run {label}: from tick {first}, {n} ticks, {amount:+.3f} {unit}")
order = [r[0] for r in runs]
if order != ["L", "F", "R"]:
    bad(f"motion order {order}, expected ['L', 'F', 'R'] (turn left, walk forward, turn right)")
else:
    (_, _, left, _), (_, _, walked, _), (_, _, right, right_start) = runs
    if left < 30:
        bad(f"turned left by {left:.1f} deg, expected >= 30")
    if walked < 0.3:
        bad(f"walked {walked:.2f} m, expected >= 0.3")
    if right > -10:
        bad(f"turned right by {right:.1f} deg, expected <= -10")
    lost = [p for p in poses if p["tick"] > right_start and not p["tracking"]]
    if not lost:
        bad("the tag never left the view after the right turn (no tick without tracking)")
    else:
        print(f"tag lost after the right turn in {len(lost)} ticks (from tick {lost[0]['tick']})")

# Came to rest: the poses of the last 0.5 s (the sequence ends with the tag at rest).
tail = [p for p in poses if p["t_ns"] >= poses[-1]["t_ns"] - 500_000_000]
if len(tail) < 2:
    bad(f"only {len(tail)} ticks in the last 0.5 s")
if any(p["yaw_deg"] != tail[0]["yaw_deg"] or p["eye"] != tail[0]["eye"] for p in tail):
    bad(f"the view still moves in the last 0.5 s ({len(tail)} ticks)")
if any(p["turn_deg_s"] != 0 or p["forward_m_s"] != 0 for p in tail):
    bad(f"non-zero velocity in the last 0.5 s ({len(tail)} ticks)")
sys.exit(0 if ok else 1)
PY
log "PASS"
