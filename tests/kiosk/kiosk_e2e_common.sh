# SPDX-License-Identifier: Apache-2.0
# Sourced by the kiosk's end-to-end scripts (e2e_netns.sh, fault_farm_restart.sh): PKI, the kiosk
# configuration, starting and stopping a farm, and the checks on the kiosk's statistics.
#
# Expects: farm kiosk tool MPIEXEC src work (set by the caller).
# Processes started here are tracked by pid / session id and stopped by id in `cleanup`.

set -u
source "$src/tests/mpi_env.sh"

CONTENT_W=480
CONTENT_H=270
JPEG_QUALITY=90
PSNR_MIN_DB=35          # decoded frame vs the farm's lossless render of the same pose, JPEG q90
SCREEN_ARGS=(--projection cylinder --screen-radius-m 3 --screen-arc-deg 150 --screen-bottom-m 0.2 --screen-top-m 2.8)

farm_sid=""             # session id of the running farm (mpirun is its leader)
kiosk_pid=""
netns_created=()

log() { echo "[$(basename "$0")] $*"; }
fail() { echo "[$(basename "$0")] FAIL: $*" >&2; exit 1; }

# All processes of the farm's session (mpirun and its ranks, which get their own process groups).
# Read from /proc/PID/stat (field 6, after the parenthesised command name), so procps is not needed.
farm_pids() {
  [[ -n "$farm_sid" ]] || return 0
  python3 - "$farm_sid" <<'PY'
import os, sys
for pid in os.listdir("/proc"):
    if not pid.isdigit():
        continue
    try:
        with open(f"/proc/{pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
    except OSError:
        continue  # gone meanwhile
    if fields[3] == sys.argv[1]:
        print(pid)
PY
}

# stop_farm [SIGNAL [WAIT_S]]: signal every process of the farm's session, wait until they are gone (up to
# WAIT_S seconds, 10 by default), then SIGKILL what is left.
stop_farm() {
  local sig=${1:-TERM} wait_s=${2:-10} pids
  pids=$(farm_pids)
  [[ -n "$pids" ]] && kill -s "$sig" $pids 2>/dev/null
  for _ in $(seq 1 $((wait_s * 10))); do
    [[ -z "$(farm_pids)" ]] && break
    sleep 0.1
  done
  pids=$(farm_pids)
  [[ -n "$pids" ]] && kill -s KILL $pids 2>/dev/null
  farm_sid=""
}

# netns_add_or_skip NS: creates network namespace NS (removed by `cleanup`) and checks that a process
# can enter it with a UTS namespace of its own, as the scripts' rsh agents do. Where this environment
# cannot (no CAP_SYS_ADMIN; a chroot or container whose / is not a mount point, where `ip netns exec`
# fails on "mount --make-rslave /"), the test is skipped (exit 77) with the reason. In CI a skip fails
# the run (.ci/check-skips): namespaces work there.
netns_add_or_skip() {
  local err
  if ! err=$(ip netns add "$1" 2>&1); then
    echo "SKIP: network namespaces are not permitted here (ip netns add: $err); run as root with CAP_SYS_ADMIN"
    exit 77
  fi
  netns_created+=("$1")
  if ! err=$(ip netns exec "$1" unshare --uts true 2>&1); then
    echo "SKIP: cannot enter a network namespace here (ip netns exec $1 unshare --uts: ${err//$'\n'/; }); run as root" \
      "on a host, VM or container whose / is a mount point"
    exit 77
  fi
}

cleanup() {
  [[ -n "$kiosk_pid" ]] && kill -s TERM "$kiosk_pid" 2>/dev/null
  stop_farm TERM
  for ns in "${netns_created[@]}"; do ip netns del "$ns" 2>/dev/null; done
}
trap cleanup EXIT

# make_pki DIR SAN: farm CA, farm certificate for SAN (its IPv6 address), appliance certificate,
# an empty revocation list; the farm serves from DIR/../farm-tls (pki export-farm: without ca.key).
make_pki() {
  "$farm" pki init-ca --dir "$1" >/dev/null || fail "pki init-ca"
  "$farm" pki issue-farm --dir "$1" --name farm --san "$2" >/dev/null || fail "pki issue-farm"
  "$farm" pki issue-appliance --dir "$1" --name museum-1 >/dev/null || fail "pki issue-appliance"
  "$farm" pki crl --dir "$1" >/dev/null || fail "pki crl"
  "$farm" pki export-farm --dir "$1" --name farm --to "$(dirname "$1")/farm-tls" >/dev/null || fail "pki export-farm"
}

# write_config FILE ENDPOINT PKI PNG_DIR PNG_EVERY [OVERRIDE...]: kiosk/config/kiosk.example.toml with the
# test's overrides (mogao-kiosk --print-config; section.key=TOML value, empty value: commented out):
# headless, the ideal 3-projector calibration at 320x240, the walk; later OVERRIDEs win.
write_config() {
  local file=$1 endpoint=$2 pki=$3 png_dir=$4 png_every=$5
  shift 5
  "$kiosk" --print-config \
    "farm.endpoint=\"$endpoint\"" "farm.ca=\"$pki/ca.pem\"" \
    "farm.cert=\"$pki/appliance-museum-1.pem\"" "farm.key=\"$pki/appliance-museum-1.key\"" \
    'outputs.backend="headless"' "outputs.png_dir=\"$png_dir\"" "outputs.png_every=$png_every" \
    'calibration.source="ideal"' 'calibration.projectors=3' 'calibration.overlap=0.15' 'calibration.output="320x240"' \
    "quality.content=\"${CONTENT_W}x${CONTENT_H}\"" 'quality.spp=1' "quality.jpeg_quality=$JPEG_QUALITY" \
    'navigation.path="walk"' 'navigation.path_frames=240' 'navigation.start=[0.0, 0.0, 4.0]' \
    'stats.file=' 'stats.log_period_s=2' "$@" > "$file" || fail "mogao-kiosk --print-config"
}

# start_farm LOG LISTEN [PREFIX...]: 3 MPI ranks serving the test room; returns once the farm logs
# that it serves (or fails).
FARM_MPI_ARGS=()        # more mpirun arguments (e2e_netns.sh multihost: host file, rsh agent)
# The farm's frame budget: off by default here, since these tests compare every shown frame with
# the farm's full render of its pose, and on the loaded machine (or under TSan) a frame may outlast
# the default 1 s and be cut. The slow-frame test sets its own.
FARM_BUDGET_ARGS=(--frame-budget-s 0)
FARM_SCENE=${FARM_SCENE:-$src/scenes/test-room.json}  # the scene served
start_farm() {
  local logf=$1 listen=$2; shift 2
  setsid "$@" "$MPIEXEC" --oversubscribe "${FARM_MPI_ARGS[@]}" -n 3 "$farm" serve --scene "$FARM_SCENE" \
    --listen "$listen" --tls-dir "$work/farm-tls" --duration-s 300 "${FARM_BUDGET_ARGS[@]}" >>"$logf" 2>&1 &
  farm_sid=$!
  disown "$farm_sid"  # stopped by session id in stop_farm; no job-control report when killed
  for _ in $(seq 1 300); do
    grep -q "render ranks, .*) on " "$logf" 2>/dev/null && return 0  # the scene loaded, not just the link
    kill -0 "$farm_sid" 2>/dev/null || { cat "$logf"; fail "the farm exited during start-up"; }
    sleep 0.1
  done
  cat "$logf"
  fail "the farm did not start within 30 s"
}

# check_stats STATS_JSON MIN_FRAMES: frames delivered, none rejected, ids strictly increasing;
# prints latency / fps / bandwidth for the test log.
check_stats() {
  python3 - "$1" "$2" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
need = int(sys.argv[2])
t = s["total"]
m = t["motion_to_photon_ms"]
print(f"frames presented {s['frames_presented']}, rejected {s['frames_rejected']}, "
      f"superseded {s['frames_superseded']}, "
      f"link sessions {s['link']['sessions_opened']}")
print(f"motion-to-photon ms: mean {m['mean']:.1f} p50 {m['p50']:.1f} p95 {m['p95']:.1f} max {m['max']:.1f}; "
      f"link (request->receive) {t['link_mean_ms']:.1f} ms, kiosk (receive->presented) {t['kiosk_mean_ms']:.1f} ms, "
      f"decode {t['decode_mean_ms']:.2f} ms")
print(f"fps {t['fps']:.1f}, bytes/frame {t['bytes_per_frame']:.0f}, "
      f"bandwidth {t['bandwidth_bytes_per_s'] / 1e6:.3f} MB/s "
      f"({t['bandwidth_bytes_per_s'] * 8 / 1e6:.2f} Mbit/s)")
ok = True
if s["frames_presented"] < need:
    print(f"FAIL: {s['frames_presented']} frames presented, {need} expected"); ok = False
if s["frames_out_of_order"] != 0:
    print(f"FAIL: {s['frames_out_of_order']} frames out of order"); ok = False
ids = [f["request_id"] for f in s["frames"]]
bad = [(a, b) for a, b in zip(ids, ids[1:]) if b <= a]
if bad:
    print(f"FAIL: request ids not strictly increasing: {bad[:5]}"); ok = False
if s["exit_code"] != 0:
    print(f"FAIL: kiosk exit code {s['exit_code']} in its statistics"); ok = False
sys.exit(0 if ok else 1)
PY
}

# check_pngs FILE...: each readable, the right size, not black (mean code > 10, < 20 % dark pixels).
check_pngs() {
  "$tool" stats "$@" > "$work/png-stats.txt" || fail "a PNG output is unreadable (corrupt)"
  python3 - "$work/png-stats.txt" <<'PY'
import sys
bad = 0
n = 0
for line in open(sys.argv[1]):
    name, w, h, mean, dark = line.split()
    n += 1
    if float(mean) <= 10 or float(dark) >= 0.2:
        print(f"FAIL: {name} is black or nearly (mean {mean}, dark fraction {dark})"); bad += 1
print(f"{n} PNG outputs checked: readable, not black")
sys.exit(1 if bad or n == 0 else 0)
PY
}

# check_psnr CONTENT_DIR REF_DIR: every dumped content frame against the farm's lossless render of its pose
# with the same samples (seed, and frame_id = the request id; PSNR >= PSNR_MIN_DB), and one frame against
# another pose's render (must be below: the comparison can fail).
check_psnr() {
  local dumps=$1 refs=$2 n=0 worst=inf first_ppm="" last_ref=""
  mkdir -p "$refs"
  for meta in "$dumps"/content-req*.json; do
    [[ -e "$meta" ]] || fail "no content frames were dumped in $dumps"
    local stem id
    stem=${meta%.json}
    id=${stem##*req}
    python3 - "$meta" "$refs/pose-$id.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
e = m["eye"]
# Path files give the floor point under the eye; the scene's eye height (test-room: 1.6 m) is added back.
json.dump({"keyframes": [{"position": [e[0], e[1] - 1.6, e[2]], "yaw_deg": m["yaw_deg"], "pitch_deg": m["pitch_deg"]}]},
          open(sys.argv[2], "w"))
PY
    "$MPIEXEC" --oversubscribe -n 1 "$farm" render --scene "$src/scenes/test-room.json" --frames 1 \
      --path "$refs/pose-$id.json" --width "$CONTENT_W" --height "$CONTENT_H" --spp 1 --jpeg-quality \
      "$JPEG_QUALITY" --first-frame-id "$id" \
      "${SCREEN_ARGS[@]}" --save-raw --contact-sheet 0 --out "$refs/req$id" >"$refs/render-$id.log" 2>&1 \
      || { cat "$refs/render-$id.log"; fail "reference render of request $id"; }
    local db
    db=$("$tool" psnr "$stem.ppm" "$refs/req$id/frame-0000.ppm") || fail "psnr of request $id"
    log "request $id: PSNR of the displayed content vs the farm's lossless render of its pose: $db dB"
    python3 -c "import sys; sys.exit(0 if float('$db') >= $PSNR_MIN_DB else 1)" \
      || fail "request $id: PSNR $db dB < $PSNR_MIN_DB dB"
    worst=$(python3 -c "print(min(float('$worst'), float('$db')))")
    [[ -z "$first_ppm" ]] && first_ppm="$stem.ppm"
    last_ref="$refs/req$id/frame-0000.ppm"
    n=$((n + 1))
  done
  (( n >= 2 )) || fail "only $n content frames dumped, 2 or more expected"
  local control
  control=$("$tool" psnr "$first_ppm" "$last_ref") || fail "psnr control"
  log "control: first dumped frame vs the last frame's reference (another pose): $control dB (must be < $PSNR_MIN_DB)"
  python3 -c "import sys; sys.exit(0 if float('$control') < $PSNR_MIN_DB else 1)" \
    || fail "the PSNR check cannot tell poses apart ($control dB)"
  log "PSNR: $n frames, worst $worst dB (bound $PSNR_MIN_DB dB at JPEG quality $JPEG_QUALITY)"
}
