#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Fault: the farm dies mid-stream (SIGKILL to every process of its session: a crash, not a clean
# stop) and comes back 5 s later on the same address. Over [::1], no namespaces needed.
# Checks, from the kiosk's statistics, log and PNG outputs:
#   * while the farm is down the outputs keep showing the last good frame: every projector PNG of
#     the display rounds between "disconnected" and "connected" is readable, not black, names the
#     request id that was on screen when the farm went away, and is identical to the first one;
#   * the kiosk reconnects by itself (a second link session, a "connected" event after the
#     "disconnected" one) and shows new frames afterwards;
#   * request ids of the frames shown stay strictly increasing across the restart (no frame shown
#     twice or out of order), none rejected; the kiosk exits 0.
#
# usage: fault_farm_restart.sh FARM KIOSK IMAGE_TOOL MPIEXEC SOURCE_DIR WORK_DIR
farm=$1 kiosk=$2 tool=$3 MPIEXEC=$4 src=$5 work=$6
source "$src/tests/kiosk/kiosk_e2e_common.sh"

rm -rf "$work"
mkdir -p "$work"
port=$((20000 + ($$ + 7919) % 20000))
endpoint="[::1]:$port"
make_pki "$work/pki" "::1"
# The farm-lost line ([status] farm_lost_after_s, 10 s by default) would be drawn over the held frame
# when the restart takes longer than that on a loaded machine; it is off here because this test
# checks the held frame itself, byte for byte (the line is tested by OnWallStatusTest).
write_config "$work/kiosk.toml" "$endpoint" "$work/pki" "$work/png" 3 'status.farm_lost_after_s=0'
start_farm "$work/farm-1.log" "$endpoint"
log "farm 1 up at $endpoint"

timeout 300 "$kiosk" --config "$work/kiosk.toml" --frames 150 --duration-s 200 --stats "$work/stats.json" \
  >"$work/kiosk.log" 2>&1 &
kiosk_pid=$!

# wait_for PATTERN SECONDS: until the kiosk's log matches (fails if the kiosk ends first).
wait_for() {
  for _ in $(seq 1 $(($2 * 10))); do
    grep -q "$1" "$work/kiosk.log" && return 0
    kill -0 "$kiosk_pid" 2>/dev/null || { cat "$work/kiosk.log"; fail "the kiosk ended while waiting for '$1'"; }
    sleep 0.1
  done
  cat "$work/kiosk.log"
  fail "no '$1' in the kiosk's log within $2 s"
}

wait_for "stats: frames=[1-9][0-9]" 120   # at least 10 frames shown from farm 1
sleep 1
log "killing farm 1 (SIGKILL to its session) mid-stream"
stop_farm KILL
wait_for "disconnected; showing request" 60
sleep 5                                  # the farm stays down: the kiosk must keep the last frame
log "restarting the farm"
start_farm "$work/farm-2.log" "$endpoint"
wait "$kiosk_pid"
rc=$?
kiosk_pid=""
stop_farm TERM
cat "$work/kiosk.log"
(( rc == 0 )) || fail "mogao-kiosk exited with $rc"

status=0
check_stats "$work/stats.json" 150 || status=1
# The down time, from the kiosk's own record: rounds between the events, and what was on screen.
python3 - "$work/stats.json" "$work/png" > "$work/down.txt" <<'PY' || status=1
import json, os, re, sys
s = json.load(open(sys.argv[1]))
ev = s["events"]
down = next((e for e in ev if e["event"] == "disconnected"), None)
if down is None:
    print("FAIL: no disconnected event", file=sys.stderr); sys.exit(1)
up = next((e for e in ev if e["event"] == "connected" and e["time_ns"] > down["time_ns"]), None)
if up is None:
    print("FAIL: the kiosk did not reconnect by itself", file=sys.stderr); sys.exit(1)
if s["link"]["sessions_opened"] < 2:
    print(f"FAIL: {s['link']['sessions_opened']} link sessions, 2 expected", file=sys.stderr); sys.exit(1)
after = [f for f in s["frames"] if f["presented_ns"] > up["time_ns"]]
if len(after) < 10:
    print(f"FAIL: only {len(after)} frames shown after the reconnect", file=sys.stderr); sys.exit(1)
if down["last_request_id"] == 0:
    print("FAIL: nothing had been shown before the farm went down", file=sys.stderr); sys.exit(1)
# Rounds while down: the longest run of display rounds without a new frame that spans the
# disconnect. Its first frame may be one still in flight when farm 1 died (presented just after the
# disconnect was noticed), its end a frame of farm 2 presented before the tick that notices the
# reconnect: the gap between presented frames is what the screen had to hold, not the events.
shown = sorted(s["frames"], key=lambda f: f["display_round"])
gaps = [(b["display_round"] - a["display_round"], a, b) for a, b in zip(shown, shown[1:])
        if a["presented_ns"] < up["time_ns"] and b["presented_ns"] > down["time_ns"]]
if not gaps:
    print("FAIL: no frame shown on both sides of the disconnect", file=sys.stderr); sys.exit(1)
_, before, after_gap = max(gaps, key=lambda g: g[0])
last, start, end = before["request_id"], before["display_round"], after_gap["display_round"] - 1
pngs = []
for name in sorted(os.listdir(sys.argv[2])):
    m = re.fullmatch(r"headless-(\d+)-(\d+)-req(\d+)\.png", name)
    if m and start < int(m.group(2)) <= end:
        pngs.append((name, int(m.group(1)), int(m.group(3))))
wrong = [p for p in pngs if p[2] != last]
if len(pngs) < 9 or wrong:
    print(f"FAIL: {len(pngs)} PNGs while down (>= 9 expected), showing other requests than {last}: {wrong[:3]}",
          file=sys.stderr); sys.exit(1)
down_s = (up["time_ns"] - down["time_ns"]) / 1e9
print(f"# farm down {down_s:.1f} s: display rounds {start + 1}..{end}, "
      f"request {last} kept on screen; {len(after)} frames after the reconnect", file=sys.stderr)
for name, output, _ in pngs:
    print(output, os.path.join(sys.argv[2], name))
PY
if (( status == 0 )); then
  mapfile -t down_pngs < <(awk '{ print $2 }' "$work/down.txt")
  check_pngs "${down_pngs[@]}" || status=1
  for output in 0 1 2; do
    mapfile -t same < <(awk -v o="$output" '$1 == o { print $2 }' "$work/down.txt")
    first=${same[0]}
    for f in "${same[@]:1}"; do
      db=$("$tool" psnr "$f" "$first") || { status=1; continue; }
      [[ "$db" == inf ]] || { log "FAIL: $f differs from $first ($db dB): the last good frame was not kept"; status=1; }
    done
    log "output $output: ${#same[@]} PNGs while the farm was down, all identical to the last good frame"
  done
fi
grep -E "disconnected|connected|reconnecting" "$work/kiosk.log" | head -5
(( status == 0 )) || fail "see above"
log "PASS"
