#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# mogao-farm-launch's choice of hosts, with a stand-in rsh agent and mpirun (no MPI, no network):
#   * a render host whose sshd comes up late (the agent refuses its first 2 checks) is waited for
#     while the machine's uptime is under MOGAO_BOOT_GRACE_S, and mpirun gets it and all 3 ranks;
#   * with MOGAO_BOOT_GRACE_S=0 (a host lost while serving) it is left out at once, 2 ranks;
#   * a host that never answers is left out when the grace ends (not waited for forever);
#   * the wait works where /proc/uptime is hidden (the unit's ProcSubset=pid; needs a mount
#     namespace, as root);
#   * a host back while the farm serves without it ends the job after 2 answers in a row
#     (MOGAO_REJOIN_CHECK_S, the second MOGAO_REJOIN_CONFIRM_S after the first), and not at all with 0;
#   * the hosts of the ranks the previous job named lost (its --lost-ranks-file) are left out unasked;
#   * a job that ends naming lost ranks is started again by the launcher at once, at most
#     MOGAO_RELAUNCH_MAX times in a row;
#   * under systemd's watchdog, mpirun's WATCHDOG_PID is its own PID (the admin rank's parent);
#   * a host file whose last line lacks its newline still has that host;
#   * bad MOGAO_BOOT_GRACE_S / MOGAO_REJOIN_CHECK_S / MOGAO_REJOIN_CONFIRM_S / RANKS are refused with
#     exit 2, naming the variable.
# usage: launch_test.sh LAUNCHER
set -euo pipefail
launcher=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

printf 'admin slots=2 # this machine\nrender2 slots=1\n' > "$work/hosts"
# The agent: "render2" refuses (as ssh does before sshd listens) until its ANSWER_AFTER-th check.
cat > "$work/agent" <<AGENT
#!/bin/sh
n=\$(cat "$work/calls" 2>/dev/null || echo 0); n=\$((n + 1)); echo \$n > "$work/calls"
[ "\$n" -gt "\${ANSWER_AFTER:-0}" ] && { echo ok; exit 0; }
echo "ssh: connect to host \$1 port 22: Connection refused" >&2; exit 255
AGENT
printf '#!/bin/sh\necho "mpirun $*"; cat "$2"\n' > "$work/mpirun"
chmod +x "$work/agent" "$work/mpirun"
run() {  # run GRACE ANSWER_AFTER: the launcher's output
  rm -f "$work/calls"
  OMPI_MCA_plm_rsh_agent="$work/agent" MOGAO_MPIRUN="${MPIRUN:-$work/mpirun}" RUNTIME_DIRECTORY="$work" \
    MOGAO_BOOT_GRACE_S=$1 ANSWER_AFTER=$2 MOGAO_REJOIN_CHECK_S=${REJOIN:-0} \
    timeout "${LIMIT:-60}" sh "$launcher" "$work/hosts" 3 mogao-farm serve 2>&1
}
up=$(cut -d. -f1 /proc/uptime)

out=$(run $((up + 600)) 2)
echo "$out" | grep -q "mpirun --hostfile .* -n 3 mogao-farm serve" || fail "booting: render2 not waited for: $out"
echo "$out" | grep -q "^render2 slots=1" || fail "booting: render2 not in the host file: $out"
echo "$out" | grep -q "asking again every 2 s" || fail "booting: the wait is not logged: $out"
[ "$(cat "$work/calls")" = 3 ] || fail "booting: render2 asked $(cat "$work/calls") times, expected 3"

# The unit's ProcSubset=pid hides /proc/uptime: here it reads empty, as in the unit's sandbox.
if unshare -m true 2>/dev/null; then
  export -f run; export launcher work
  out=$(unshare -m bash -c "mount --bind /dev/null /proc/uptime && run $((up + 600)) 2")
  echo "$out" | grep -q "mpirun --hostfile .* -n 3 mogao-farm serve" \
    || fail "/proc/uptime hidden: render2 not waited for: $out"
  hidden="waits with /proc/uptime hidden, "
else
  echo "note: no mount namespace here (not root): the wait with /proc/uptime hidden is not checked"
fi

out=$(run 0 2)
refused="render host render2 left out: health check failed (exit 255: ssh: connect to host render2 port 22:"
refused="$refused Connection refused"
echo "$out" | grep -q "$refused" \
  || fail "serving: render2 not left out with the reason: $out"
echo "$out" | grep -q "mpirun --hostfile .* -n 2 mogao-farm serve" || fail "serving: expected 2 ranks: $out"
[ "$(cat "$work/calls")" = 1 ] || fail "serving: render2 asked $(cat "$work/calls") times, expected 1 (no wait)"

start=$(date +%s)
out=$(run $(($(cut -d. -f1 /proc/uptime) + 4)) 1000)
took=$(($(date +%s) - start))
echo "$out" | grep -q "render host render2 left out" || fail "grace over: render2 not left out: $out"
((took >= 3 && took <= 15)) || fail "grace over: the launcher took $took s for a 4 s grace"

# Serving without render2, which comes back: with MOGAO_REJOIN_CHECK_S=1 the watcher asks it every
# second and ends the job (SIGTERM to mpirun, which exits 1 as Open MPI's does) once it has answered
# twice in a row: checks 2 (refused), 3 and 4 (answers). Without the watcher the job runs on.
cat > "$work/mpirun-serving" <<'MPI'
#!/bin/sh
echo "mpirun $*"
trap 'echo "mpirun: SIGTERM"; exit 1' TERM
while :; do sleep 0.1; done
MPI
chmod +x "$work/mpirun-serving"
start=$(date +%s)
rc=0; out=$(REJOIN=1 MPIRUN="$work/mpirun-serving" LIMIT=30 run 0 2) || rc=$?
rejoin_took=$(($(date +%s) - start))
[ $rc = 1 ] || fail "rejoin: exit $rc, expected 1 (the job ended by SIGTERM): $out"
echo "$out" | grep -q "mpirun: SIGTERM" || fail "rejoin: mpirun not ended: $out"
echo "$out" | grep -q "render host(s) render2 answer again (2 checks in a row, 1 s apart)" \
  || fail "rejoin: not logged: $out"
[ "$(cat "$work/calls")" = 4 ] || fail "rejoin: render2 asked $(cat "$work/calls") times, expected 4"
# The confirming check comes MOGAO_REJOIN_CONFIRM_S after the first answer, not a whole period later:
# checks at 5 s (answers) and 6 s end the job, where two periods would take 10 s.
start=$(date +%s)
rc=0; out=$(MOGAO_REJOIN_CONFIRM_S=1 REJOIN=5 MPIRUN="$work/mpirun-serving" LIMIT=30 run 0 1) || rc=$?
confirm_took=$(($(date +%s) - start))
echo "$out" | grep -q "answer again (2 checks in a row, 1 s apart)" || fail "rejoin confirm: not logged: $out"
[ "$(cat "$work/calls")" = 3 ] || fail "rejoin confirm: render2 asked $(cat "$work/calls") times, expected 3"
((confirm_took < 9)) || fail "rejoin confirm: the job ended after $confirm_took s, expected about 6 (not 10)"
rc=0; out=$(REJOIN=0 MPIRUN="$work/mpirun-serving" LIMIT=4 run 0 2) || rc=$?
[ $rc = 124 ] || fail "no rejoin (MOGAO_REJOIN_CHECK_S=0): the job ended (exit $rc): $out"

# The previous job named rank 2 lost (the admin's --lost-ranks-file, beside the host file it ran on):
# render2 is left out unasked, even within the boot grace and though it would answer, the file is
# consumed, and mpirun's job is told where to write it.
printf 'admin slots=2\nrender2 slots=1\n' > "$work/farm-hosts.live"
printf '2\n' > "$work/lost-ranks"
out=$(LIMIT=10 run $((up + 600)) 0)
echo "$out" | grep -q "render host render2 left out unasked: named lost by the previous job (rank 2)" \
  || fail "named lost: render2 not left out with the reason: $out"
echo "$out" | grep -q "mpirun --hostfile .* -n 2 mogao-farm serve --lost-ranks-file $work/lost-ranks$" \
  || fail "named lost: expected 2 ranks and the lost-ranks file: $out"
[ ! -e "$work/calls" ] || fail "named lost: render2 asked $(cat "$work/calls") times, expected 0"
[ ! -e "$work/lost-ranks" ] || fail "named lost: the file was not consumed"
# Only the admin's own rank named (or nothing readable): every render host is asked as usual.
printf 'admin slots=2\nrender2 slots=1\n' > "$work/farm-hosts.live"
printf '1\nx\n' > "$work/lost-ranks"
out=$(run 0 0)
echo "$out" | grep -q "mpirun --hostfile .* -n 3 mogao-farm serve" || fail "admin rank named: render2 dropped: $out"
[ "$(cat "$work/calls")" = 1 ] || fail "admin rank named: render2 asked $(cat "$work/calls") times, expected 1"

# A job that ends naming rank 2 lost (as the admin does before it aborts) is started again by the
# launcher itself, at once, without render2 and without asking it; a job that keeps naming lost
# ranks is started again at most MOGAO_RELAUNCH_MAX times, then the launcher exits with its status.
cat > "$work/mpirun-loses" <<'MPI'
#!/bin/sh
n=$(cat "$WORK/jobs" 2>/dev/null || echo 0); n=$((n + 1)); echo $n > "$WORK/jobs"
echo "mpirun $*"
for last; do :; done
[ "$n" -le "${LOSE_JOBS:-1}" ] || exit 0
echo 2 > "$last"; exit 3
MPI
chmod +x "$work/mpirun-loses"
rm -f "$work/jobs" "$work/lost-ranks"
rc=0; out=$(WORK=$work MPIRUN="$work/mpirun-loses" LIMIT=20 run 0 0) || rc=$?
[ $rc = 0 ] || fail "relaunch: exit $rc, expected 0 from the second job: $out"
[ "$(cat "$work/jobs")" = 2 ] || fail "relaunch: $(cat "$work/jobs") jobs, expected 2: $out"
echo "$out" | grep -q "the job ended (exit 3) naming lost rank(s) 2: starting it again" \
  || fail "relaunch: not logged: $out"
echo "$out" | grep -q "render host render2 left out unasked: named lost by the previous job (rank 2)" \
  || fail "relaunch: render2 not left out unasked: $out"
[ "$(echo "$out" | grep -c "mpirun --hostfile .* -n 2 mogao-farm serve")" = 1 ] \
  || fail "relaunch: the second job should have 2 ranks: $out"
[ "$(cat "$work/calls")" = 1 ] || fail "relaunch: render2 asked $(cat "$work/calls") times, expected 1 (first start)"
rm -f "$work/jobs" "$work/lost-ranks"
rc=0; out=$(WORK=$work MPIRUN="$work/mpirun-loses" LOSE_JOBS=9 MOGAO_RELAUNCH_MAX=2 LIMIT=20 run 0 0) || rc=$?
[ $rc = 3 ] || fail "relaunch limit: exit $rc, expected the job's 3: $out"
[ "$(cat "$work/jobs")" = 3 ] || fail "relaunch limit: $(cat "$work/jobs") jobs, expected 1 + 2 relaunches: $out"
rm -f "$work/jobs" "$work/lost-ranks"
rc=0; out=$(WORK=$work MPIRUN="$work/mpirun-loses" MOGAO_RELAUNCH_MAX=0 LIMIT=20 run 0 0) || rc=$?
[ $rc = 3 ] && [ "$(cat "$work/jobs")" = 1 ] || fail "MOGAO_RELAUNCH_MAX=0: exit $rc, $(cat "$work/jobs") jobs: $out"
[ -s "$work/lost-ranks" ] || fail "MOGAO_RELAUNCH_MAX=0: the lost ranks are not left for systemd's restart"
rm -f "$work/jobs" "$work/lost-ranks"

# Under systemd's watchdog (WATCHDOG_PID names the unit's main process, the launcher) mpirun gets its
# own PID as WATCHDOG_PID: the admin rank pings the watchdog only when it names the rank's parent.
printf '#!/bin/sh\necho "watchdog pid ${WATCHDOG_PID:-none} own $$"\n' > "$work/mpirun-pid"
chmod +x "$work/mpirun-pid"
out=$(WATCHDOG_PID=1 MPIRUN="$work/mpirun-pid" run 0 0)
echo "$out" | grep -Eq "^watchdog pid ([0-9]+) own \1$" || fail "WATCHDOG_PID is not mpirun's own PID: $out"
out=$(MPIRUN="$work/mpirun-pid" run 0 0)
echo "$out" | grep -q "^watchdog pid none own" || fail "WATCHDOG_PID set without systemd's watchdog: $out"

# A host file whose last line has no newline: its host is still asked and used.
printf 'admin slots=2\nrender2 slots=1' > "$work/hosts"
out=$(run 0 0)
echo "$out" | grep -q "mpirun --hostfile .* -n 3 mogao-farm serve" || fail "no final newline: render2 dropped: $out"
printf 'admin slots=2 # this machine\nrender2 slots=1\n' > "$work/hosts"

rc=0; err=$(sh "$launcher" "$work/hosts" 0 true 2>&1) || rc=$?
[ $rc = 2 ] && echo "$err" | grep -q "RANKS must be a number >= 1" || fail "RANKS 0: rc $rc, '$err'"
for bad in "MOGAO_BOOT_GRACE_S=-1" "MOGAO_BOOT_GRACE_S=2m" "MOGAO_REJOIN_CHECK_S=1.5" "MOGAO_REJOIN_CONFIRM_S=x"; do
  rc=0; err=$(env "$bad" sh "$launcher" "$work/hosts" 3 true 2>&1) || rc=$?
  [ $rc = 2 ] && echo "$err" | grep -q "${bad%%=*} must be whole seconds" || fail "$bad: rc $rc, '$err'"
done
rc=0; err=$(MOGAO_RELAUNCH_MAX=-1 sh "$launcher" "$work/hosts" 3 true 2>&1) || rc=$?
[ $rc = 2 ] && echo "$err" | grep -q "MOGAO_RELAUNCH_MAX must be a whole number" \
  || fail "RELAUNCH_MAX -1: rc $rc, '$err'"
echo "PASS: launcher waits for booting hosts only within the grace (3 checks)," \
  "${hidden:-}leaves lost ones out at once (named ones unasked), ends the wait at the grace ($took s)," \
  "starts a job that named lost ranks again itself," \
  "restarts for a host back after 2 checks ($rejoin_took s at 1 s a check; $confirm_took s at 5 s, confirmed 1 s later)"
