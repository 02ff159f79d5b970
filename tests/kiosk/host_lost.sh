#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Fault: a render host of a multi-host farm is lost while the farm serves an appliance, twice, and
# then one comes back (render-node failure: docs/services.md "Render-node failure"):
#   cut   render host R2's link goes down (a hung or unreachable host: its rank no longer answers,
#         nothing reports an error; the admin's liveness check ends the job when the rank's heartbeat
#         has been silent for its limit, renderfarm/farm/rank_liveness.h)
#   dead  render host R1 dies: SIGKILL to every process in its namespace, and its link goes down
#   back  R2's link comes up again: the launcher's watcher (MOGAO_REJOIN_CHECK_S=2) sees it answer
#         twice in a row and ends the job, and the restarted farm renders on R2 again
# After a loss the launcher starts the job again itself; for a return the farm is restarted by a loop
# standing in for systemd's Restart=on-failure (RestartSec=500ms, as the unit has it), through
# systemd/mogao-farm-launch as the unit runs it. The launcher leaves out the host the admin named
# lost, asks each other render host for `mogao-farm health` through the rsh agent, leaves out the
# one that does not answer within 2 s and starts mpirun over the others. After the first fault the farm
# serves with one render rank (R1), after the second with the admin alone (which then renders), and
# after R2's return with R2.
# Checks: the launcher names the host it left out each time; the farm comes back with 1, then 0, then 1
# render ranks; from the kiosk's own record, the appliance shows a new frame within 10 s of each
# loss (the recovery bound) and within 10 s of the job's end for R2's return, request ids strictly
# increasing across the restarts, the last good frame held meanwhile (no frame rejected), and it
# ends with exit code 0.
#
# Topology: the admin (mpirun, rank 0) in namespace A; render hosts R1 (10.77.2.2) and R2
# (10.77.2.3), one slot each, on a bridge in A (10.77.2.1) that Open MPI's TCP transport must use;
# mpirun and the launcher reach them through an rsh agent that enters their namespace (a stand-in
# for ssh, as in e2e_netns.sh multihost); the kiosk in namespace K reaches A over IPv6.
#
# usage: host_lost.sh FARM KIOSK IMAGE_TOOL MPIEXEC SOURCE_DIR WORK_DIR
farm=$1 kiosk=$2 tool=$3 MPIEXEC=$4 src=$5 work=$6
source "$src/tests/kiosk/kiosk_e2e_common.sh"
launcher="$src/systemd/mogao-farm-launch"
RESUME_LIMIT_S=10

rm -rf "$work"
mkdir -p "$work"
A="mogao-hl-a-$$" K="mogao-hl-k-$$" R1="mogao-hl-r1-$$" R2="mogao-hl-r2-$$"
netns_add_or_skip "$A"
for ns in "$K" "$R1" "$R2"; do
  ip netns add "$ns" || fail "ip netns add $ns"
  netns_created+=("$ns")
  ip -n "$ns" link set lo up
done
ip -n "$A" link set lo up
# Appliance link (IPv6), as in e2e_netns.sh.
ip link add "hla$$" netns "$A" type veth peer name "hlk$$" netns "$K" || fail "veth pair A-K"
ip -n "$A" -6 addr add fd00:6d6f::1/64 dev "hla$$" nodad
ip -n "$K" -6 addr add fd00:6d6f::2/64 dev "hlk$$" nodad
ip -n "$A" link set "hla$$" up
ip -n "$K" link set "hlk$$" up
# Farm network: a bridge in A with one veth per render host, so R1 and R2 also reach each other.
ip -n "$A" link add "hlbr$$" type bridge || fail "bridge in $A"
ip -n "$A" addr add 10.77.2.1/24 dev "hlbr$$"
ip -n "$A" link set "hlbr$$" up
i=2
for ns in "$R1" "$R2"; do
  ip link add "hlb$i$$" netns "$A" type veth peer name "hlr$i$$" netns "$ns" || fail "veth pair A-$ns"
  ip -n "$A" link set "hlb$i$$" master "hlbr$$"
  ip -n "$A" link set "hlb$i$$" up
  ip -n "$ns" addr add "10.77.2.$i/24" dev "hlr$i$$"
  ip -n "$ns" link set "hlr$i$$" up
  i=$((i + 1))
done

# The rsh agent: "agent HOST COMMAND..." runs COMMAND on HOST by entering its namespace with its own
# host name. A host whose link is down does not answer, like ssh to it (the agent waits until the
# host's farm interface is up; iputils' ping is not among the project's packages).
cat > "$work/rsh-agent" <<AGENT
#!/bin/sh
host=\$1; shift
case \$host in
  10.77.2.1) exec ip netns exec $A unshare --uts sh -c "hostname farm-admin; \$*" ;;
  10.77.2.2) ns=$R1 name=farm-render1 dev=hlr2$$ ;;
  10.77.2.3) ns=$R2 name=farm-render2 dev=hlr3$$ ;;
  *) echo "rsh-agent: unknown host \$host" >&2; exit 1 ;;
esac
until ip -n "\$ns" link show up dev "\$dev" | grep -q .; do sleep 0.2; done
exec ip netns exec "\$ns" unshare --uts sh -c "hostname \$name; \$*"
AGENT
chmod +x "$work/rsh-agent"
printf '# admin first (rank 0)\n10.77.2.1 slots=1\n10.77.2.2 slots=1\n10.77.2.3 slots=1\n' > "$work/farm-hosts"

make_pki "$work/pki" "fd00:6d6f::1"
endpoint="[fd00:6d6f::1]:7443"
# The farm-lost line stays off: the held frame is checked through the statistics, not its pixels.
write_config "$work/kiosk.toml" "$endpoint" "$work/pki" "$work/png" 1000 'status.farm_lost_after_s=0'

# The restart loop: the unit's ExecStart (launcher + farm), restarted 1 s after a failure.
cat > "$work/supervise" <<SUP
#!/bin/bash
export OMPI_MCA_pml=ob1 OMPI_MCA_osc=^ucx OMPI_MCA_memory=^patcher
export OMPI_MCA_plm_rsh_agent=$work/rsh-agent OMPI_MCA_btl=self,vader,tcp
export OMPI_MCA_btl_tcp_if_include=10.77.2.0/24 OMPI_MCA_oob_tcp_if_include=10.77.2.0/24
export MOGAO_MPIRUN="$MPIEXEC --oversubscribe" RUNTIME_DIRECTORY=$work
# A lost host while serving: the launcher must not wait for it (the boot grace is for booting farms).
export MOGAO_BOOT_GRACE_S=0 MOGAO_REJOIN_CHECK_S=2
source "$src/tests/mpi_env.sh"
for start in 1 2 3 4 5 6; do
  echo "supervise: start \$start at \$(date +%s%N)"
  "$launcher" "$work/farm-hosts" 3 "$farm" serve --scene "$src/scenes/test-room.json" --listen "[::]:7443" \
    --tls-dir "$work/farm-tls" --duration-s 300
  rc=\$?
  echo "supervise: exit \$rc at \$(date +%s%N)"
  [ \$rc -eq 0 ] && exit 0
  sleep 0.5
done
SUP
chmod +x "$work/supervise"
setsid ip netns exec "$A" unshare --uts sh -c 'hostname farm-admin; exec "$@"' farm-admin "$work/supervise" \
  >>"$work/farm.log" 2>&1 &
farm_sid=$!
disown "$farm_sid"

# wait_farm N_RENDER SECONDS: until the farm's log has its Nth "serving" line with that many
# render ranks.
wait_serving() {
  local nth=$1 ranks=$2
  for _ in $(seq 1 600); do
    (( $(grep -c "render ranks, .*) on " "$work/farm.log") >= nth )) && break
    sleep 0.1
  done
  grep "render ranks, .*) on " "$work/farm.log" | sed -n "${nth}p" | grep -q "($ranks render rank" ||
    { cat "$work/farm.log"; fail "start $nth of the farm does not serve with $ranks render ranks"; }
}
wait_serving 1 2
log "farm up over 3 hosts (2 render ranks)"

ip netns exec "$K" timeout 300 "$kiosk" --config "$work/kiosk.toml" --frames 1000000 --duration-s 200 \
  --stats "$work/stats.json" >"$work/kiosk.log" 2>&1 &
kiosk_pid=$!
# wait_frames N SECONDS: until the kiosk's periodic stats line reports at least N frames more than now.
frames_now() { grep -o "stats: frames=[0-9]*" "$work/kiosk.log" | tail -1 | cut -d= -f2; }
wait_frames() {
  local base
  base=$(frames_now); base=${base:-0}
  for _ in $(seq 1 $(($2 * 10))); do
    local now; now=$(frames_now)
    (( ${now:-0} >= base + $1 )) && return 0
    kill -0 "$kiosk_pid" 2>/dev/null || { cat "$work/kiosk.log"; fail "the kiosk ended early"; }
    sleep 0.1
  done
  cat "$work/kiosk.log" "$work/farm.log"
  fail "the kiosk did not show $1 more frames within $2 s"
}
wait_frames 10 120

log "cut: render host R2's link goes down"
t_cut=$(date +%s%N)
ip -n "$R2" link set "hlr3$$" down
wait_serving 2 1
wait_frames 10 120

log "dead: render host R1 is killed (every process) and its link goes down"
t_dead=$(date +%s%N)
ip -n "$R1" link set "hlr2$$" down
pids=$(ip netns pids "$R1")
[[ -n "$pids" ]] && kill -KILL $pids
wait_serving 3 1  # the admin alone renders (it counts itself then)
wait_frames 10 120

log "back: render host R2's link comes up again"
t_back=$(date +%s%N)
ip -n "$R2" link set "hlr3$$" up
wait_serving 4 1  # R2 renders again (R1 stays out)
wait_frames 10 120

kill -TERM "$kiosk_pid"
wait "$kiosk_pid"
rc=$?
kiosk_pid=""
stop_farm TERM
grep -E "mogao-farm-launch|supervise|did not reply|serving" "$work/farm.log"
grep -q "render host(s) 10.77.2.3 answer again" "$work/farm.log" ||
    fail "the launcher's watcher did not name R2 (10.77.2.3) back"
(( rc == 0 )) || { cat "$work/kiosk.log"; fail "mogao-kiosk exited with $rc"; }
grep -q "render host 10.77.2.3 left out" "$work/farm.log" || fail "the launcher did not name R2 (10.77.2.3) as left out"
grep -q "render host 10.77.2.2 left out" "$work/farm.log" || fail "the launcher did not name R1 (10.77.2.2) as left out"

status=0
check_stats "$work/stats.json" 30 || status=1
python3 - "$work/stats.json" "$t_cut" "$t_dead" "$RESUME_LIMIT_S" "$work/farm.log" "$t_back" <<'PY' || status=1
import json, re, sys
s = json.load(open(sys.argv[1]))
supervise = [(m.group(1), int(m.group(2))) for m in
             (re.match(r"supervise: (start|exit) \d+ at (\d+)", l) for l in open(sys.argv[5])) if m]
limit = float(sys.argv[4])
frames = sorted(s["frames"], key=lambda f: f["presented_ns"])
ok = True
for name, t in (("cut", int(sys.argv[2])), ("dead", int(sys.argv[3])), ("back", int(sys.argv[6]))):
    # The first frame of the restarted farm: the first one presented after a "connected" event
    # that follows the loss.
    up = next((e for e in s["events"] if e["event"] == "connected" and e["time_ns"] > t), None)
    if up is None:
        print(f"FAIL({name}): the kiosk did not reconnect after the loss"); ok = False; continue
    first = next((f for f in frames if f["presented_ns"] > up["time_ns"]), None)
    if first is None:
        print(f"FAIL({name}): no frame shown after the reconnect"); ok = False; continue
    resume = (first["presented_ns"] - t) / 1e9
    ended = next((ns for what, ns in supervise if what == "exit" and ns > t), None)
    started = next((ns for what, ns in supervise if what == "start" and ns > t), None)
    # A loss's job is started again by the launcher itself (no supervise line); a return's by the loop.
    if ended and started and ended < first["presented_ns"]:
        steps = f"job ended +{(ended - t) / 1e9:.1f} s, restarted +{(started - t) / 1e9:.1f} s, "
    else:
        steps, ended = "job started again by the launcher, ", None
    print(f"{name}: new frame on the wall {resume:.1f} s after the {'return' if name == 'back' else 'loss'} "
          f"(request {first['request_id']}; {steps}kiosk reconnected +{(up['time_ns'] - t) / 1e9:.1f} s)")
    # A return: the watcher takes 2 checks to trust it; the appliance's wait is from the job's end.
    gap = (first["presented_ns"] - ended) / 1e9 if name == "back" and ended else resume
    if name == "back":
        print(f"back: the restart for R2 kept the wall waiting {gap:.1f} s (job ended to new frame)")
    if gap > limit:
        print(f"FAIL({name}): {gap:.1f} s > {limit:.0f} s"); ok = False
if s["frames_rejected"] != 0:
    print(f"FAIL: {s['frames_rejected']} frames rejected"); ok = False
sys.exit(0 if ok else 1)
PY
(( status == 0 )) || fail "see above"
log "PASS"
