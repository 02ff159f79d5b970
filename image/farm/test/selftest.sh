#!/bin/sh
# SPDX-License-Identifier: Apache-2.0
# Runs INSIDE a render host under QEMU (image/farm/test/farm_qemu_test.py), as root, from the
# test-only unit mogao-farm-selftest.service that the test provisions into its copy of the image:
#   selftest.sh admin    the admin host: mogao-farm.service (mpirun + ranks)
#   selftest.sh render   a render host: sshd, ranks started over ssh
# Results go to the first serial port as lines "MOGAO-SELFTEST <key> [k=v ...]"; the host answers
# on the second serial port (one line per request).
set -u
role=${1:?role: admin or render}
out=/dev/ttyS0
ctl=/dev/ttyS1
unit=mogao-farm.service
fails=0

say() { echo "MOGAO-SELFTEST $*" > "$out"; }
ok() { say "ok $*"; }
bad() { say "FAIL $*"; fails=$((fails + 1)); }
uptime_s() { cut -d' ' -f1 /proc/uptime; }
prop() { systemctl show -P "$2" "$1" 2>/dev/null; }
host_wait() { timeout "$1" head -n1 "$ctl" 2>/dev/null | tr -d '\r'; }
journal() { journalctl -b -u "$1" --no-pager -o cat 2>/dev/null; }
dump_journal() { journal "$1" | tail -n "${2:-40}" | sed 's/^/MOGAO-SELFTEST log /' > "$out"; }
# The environment variable $2 of process $1 (root reads every process's environ).
proc_env() { tr '\0' '\n' < "/proc/$1/environ" 2>/dev/null | sed -n "s/^$2=//p"; }
# Processes named mogao-farm (the ranks), as "pid:uid:rank:seccomp:nonewprivs" words.
ranks() {
  local p
  for p in $(pgrep -x mogao-farm); do
    # MPI ranks only: the launcher's `mogao-farm health` check over ssh is one too, for a moment.
    [ -n "$(proc_env "$p" OMPI_COMM_WORLD_RANK)" ] || continue
    printf '%s:%s:%s:%s:%s ' "$p" "$(awk '/^Uid:/ { print $2 }' /proc/$p/status)" \
      "$(proc_env "$p" OMPI_COMM_WORLD_RANK)" \
      "$(awk '/^Seccomp:/ { print $2 }' /proc/$p/status)" "$(awk '/^NoNewPrivs:/ { print $2 }' /proc/$p/status)"
  done
}
# Listening sockets (ss -ltnup), one marker per line: "listen tcp [::]:7443 mogao-farm".
listeners() {
  ss -Htlnup 2>/dev/null | awk '{ n = split($NF, a, "\""); print "listen " $1 " " $5 " " (n > 1 ? a[2] : "?") }' |
    while read -r line; do say "$line"; done
}
diagnose() {
  ps -eo pid,ppid,user,stat,wchan:24,comm | grep -E ' (mpirun|orted|mogao-farm|ssh|sshd)$' \
    | sed 's/^/MOGAO-SELFTEST diag ps /' > "$out"
  for p in $(pgrep -x mogao-farm); do
    ps -L -o tid,stat,wchan:24,time,pcpu -p "$p" | sed "s/^/MOGAO-SELFTEST diag threads $p /" > "$out"
  done
  ss -Htanp 2>/dev/null | grep -v LISTEN | sed 's/^/MOGAO-SELFTEST diag ss /' > "$out"
  # TCP's own view of each connection (mss, rtt, retransmits, bytes acked) and the NIC's counters:
  # tells a lost path (retransmits, nothing acked) from peers that wait on each other.
  ss -Htinp state established 2>/dev/null | paste - - | sed 's/^/MOGAO-SELFTEST diag tcp /' > "$out"
  ip -s -o link show 2>/dev/null | sed 's/^/MOGAO-SELFTEST diag link /' > "$out"
  grep '^Tcp:' /proc/net/snmp | paste - - | sed 's/^/MOGAO-SELFTEST diag snmp /' > "$out"
}
check_common() {
  failed=$(systemctl --failed --plain --no-legend 2>/dev/null | awk '{print $1}' | tr '\n' ' ')
  [ -z "$failed" ] && ok "no-failed-units" || bad "failed-units $failed"
  pw=$(awk -F: '$2 !~ /^[*!]/ { print $1 }' /etc/shadow | tr '\n' ' ')
  [ -z "$pw" ] && ok "no-passwords" || bad "accounts-with-password $pw"
  ok "units running=$(systemctl list-units --type=service --state=running --plain --no-legend |
    awk '{print $1}' | tr '\n' ',')"
}

stty -F "$ctl" -echo icanon 2>/dev/null
say "start role=$role uptime=$(uptime_s) host=$(hostname)" \
    "addrs=$(ip -br addr show scope global | awk '{ $1 = $2 = ""; print }' | tr -s ' ' ',')"

# --- what docs/packaging.md tells a technician: the package with apt (offline here: the image holds
# its dependencies), then the site's files; the test provisioned both under $stage ------------------
stage=/var/lib/mogao-test
since() { awk -v a="$1" -v b="$(uptime_s)" 'BEGIN { printf "%.1f", b - a }'; }
install_package() {
  deb=$(ls "$stage"/mogao-farm_*.deb 2> /dev/null | head -n1) t0=$(uptime_s)
  if [ -n "$deb" ] && DEBIAN_FRONTEND=noninteractive apt install -y "$deb" > "$stage/apt.log" 2>&1; then
    ok "package-installed seconds=$(since "$t0") version=$(dpkg-query -W -f '${Version}' mogao-farm)"
  else
    bad "package-installed deb='$deb'"
    tail -n 30 "$stage/apt.log" | sed 's/^/MOGAO-SELFTEST log /' > "$out"
  fi
  # What the package made: its user (fixed ids, the home sshd reads), the unit enabled but not
  # started (no TLS files yet).
  user=$(getent passwd mogao-farm | cut -d: -f3,4,6)
  st="user=$user enabled=$(systemctl is-enabled $unit 2> /dev/null) active=$(systemctl is-active $unit 2> /dev/null)"
  if [ "$user" = 971:971:/var/lib/mogao-farm ] && [ "$(systemctl is-enabled $unit 2> /dev/null)" = enabled ] &&
     [ "$(systemctl is-active $unit 2> /dev/null)" = inactive ]; then
    ok "package-state $st"
  else
    bad "package-state $st"
  fi
  # The site's files: the farm's readable by its group only, the farm user's ssh files its own.
  cp -a "$stage/site/." /
  chown -R root:mogao-farm /etc/mogao
  find /etc/mogao -type d -exec chmod 0750 {} +
  find /etc/mogao -type f -exec chmod 0640 {} +
  if [ -d /var/lib/mogao-farm/.ssh ]; then
    chown -R mogao-farm:mogao-farm /var/lib/mogao-farm/.ssh
    chmod 0700 /var/lib/mogao-farm/.ssh
    find /var/lib/mogao-farm/.ssh -type f -exec chmod 0600 {} +
    find /var/lib/mogao-farm/.ssh -type f -name '*.pub' -exec chmod 0644 {} +
  fi
  # The packet filter reads the link port from farm.env, which is new.
  systemctl reload mogao-farm-firewall.service || bad "firewall-reload"
  ok "site-configured uptime=$(uptime_s)"
}
install_package

if [ "$role" = render ]; then
  i=0
  while [ "$(systemctl is-active ssh.service)" != active ] && [ $i -lt 120 ]; do sleep 1; i=$((i + 1)); done
  [ "$(systemctl is-active ssh.service)" = active ] && ok "sshd-active uptime=$(uptime_s)" \
    || { bad "sshd-active"; dump_journal ssh.service; }
  ok "farm-unit-here state=$(systemctl is-active $unit) condition=$(prop $unit ConditionResult)"
  # The admin's mpirun logs in over ssh and starts orted, which starts this host's rank (unless
  # the test runs every rank on the admin: /etc/mogao/no-ranks-here, test copy only).
  i=0 r=""
  [ -f /etc/mogao/no-ranks-here ] && i=100000
  while [ $i -lt 900 ]; do
    r=$(ranks); [ -n "$r" ] && break
    sleep 1; i=$((i + 1))
  done
  pid=""
  if [ -f /etc/mogao/no-ranks-here ]; then
    say "skip rank-running (every rank runs on the admin in this test)"
  elif [ -n "$r" ]; then
    pid=${r%%:*}
    ok "rank-running uptime=$(uptime_s) ranks=$r" \
       "parent=$(ps -o comm= -p "$(ps -o ppid= -p "$pid" | tr -d ' ')") user=$(ps -o user= -p "$pid")"
  else
    bad "rank-running (no mogao-farm process in 900 s)"; dump_journal ssh.service
  fi
  sleep 5
  listeners
  diagnose
  say "rank-ready"
  answer=$(host_wait 900); say "host said '$answer'"
  # After the admin's watchdog restart: the old rank is gone, a new one runs.
  i=0 r2=""
  [ -z "$pid" ] && i=100000
  while [ $i -lt 600 ]; do
    r2=$(ranks); [ -n "$r2" ] && [ "${r2%%:*}" != "$pid" ] && break
    sleep 1; i=$((i + 1))
  done
  if [ -z "$pid" ]; then say "skip rank-restarted (no rank here)"
  elif [ -n "$r2" ] && [ "${r2%%:*}" != "$pid" ]; then ok "rank-restarted ranks=$r2 old_pid=$pid"
  else bad "rank-restarted (ranks now '$r2', before $pid)"; fi
  ok "ssh-logins $(journal ssh.service | grep -c 'Accepted publickey for mogao-farm')" \
     "refused=$(journal ssh.service | grep -ciE 'Failed|Invalid user')"
  check_common
  say "done fails=$fails uptime=$(uptime_s)"
  exit 0
fi

# --- admin: once farm-render2 answers the farm's ssh login with its package installed (else the
# launcher's health check would leave it out), `systemctl enable --now mogao-farm` ----------------------
t0=$(uptime_s) i=0
until runuser -u mogao-farm -- ssh -o BatchMode=yes -o ConnectTimeout=10 farm-render2 mogao-farm --version \
    > /dev/null 2>&1; do
  i=$((i + 1)); [ $i -ge 120 ] && break
  sleep 5
done
[ $i -lt 120 ] && ok "render-host-answers seconds=$(since "$t0")" \
  || bad "render-host-answers (farm-render2: no ssh login or no mogao-farm there)"
systemctl enable --now --no-block $unit

# --- admin: mogao-farm.service reaches READY (Type=notify: active == READY=1 received) ------------
# READY comes ~10 s after ExecStart under TCG; each round here takes 1-2 s of the guest.
state="" i=0
while [ $i -lt 300 ]; do
  state=$(systemctl is-active $unit)
  [ "$state" = active ] && break
  [ $((i % 30)) -eq 0 ] && say "waiting farm state=$state restarts=$(prop $unit NRestarts) uptime=$(uptime_s)"
  # Stuck starting: what the farm's processes wait for.
  [ $i -eq 120 ] && { diagnose; dump_journal $unit 200; }
  [ "$state" = failed ] && break
  sleep 1; i=$((i + 1))
done
r_ready=$(prop $unit NRestarts)
if [ "$state" = active ]; then
  ok "farm-ready uptime=$(uptime_s) ready_us=$(prop $unit ActiveEnterTimestampMonotonic)" \
     "exec_us=$(prop $unit ExecMainStartTimestampMonotonic) restarts=$(prop $unit NRestarts)" \
     "pid=$(prop $unit MainPID)" \
     "main=$(ps -o comm= -p "$(prop $unit MainPID)") user=$(ps -o user= -p "$(prop $unit MainPID)")"
else
  bad "farm-ready state=$state restarts=$(prop $unit NRestarts) result=$(prop $unit Result)"
fi
dump_journal $unit 30
say "boot userspace_us=$(systemctl show -P UserspaceTimestampMonotonic)" \
    "network_online_us=$(prop network-online.target ActiveEnterTimestampMonotonic)" \
    "ssh_us=$(prop ssh.service ActiveEnterTimestampMonotonic)"
sleep 5
r=$(ranks)
ok "ranks $r"
listeners
score=$(systemd-analyze security $unit 2>/dev/null | tail -n1)
say "security-online $score"
systemd-analyze security $unit 2>/dev/null | awk '$1 == "✗" { $1 = ""; print "exposed" $0 }' | head -n 60 |
  while read -r line; do say "$line"; done
say "farm-ready"

# --- the host's kiosk streams; afterwards the farm must still be up, without new restarts, after
# more than WatchdogSec (the admin rank's WATCHDOG=1 pings arrive through mpirun) ----------------------
answer=$(host_wait 900); say "host said '$answer'"
wd_us=$(prop $unit WatchdogUSec)
[ -z "$wd_us" ] && wd_us=0
ready_us=$(prop $unit ActiveEnterTimestampMonotonic)
case $wd_us in
  *min*|*s) wd_s=$(systemd-analyze timespan "$wd_us" 2>/dev/null | awk '/μs:|us:/ { print int($2 / 1000000) }') ;;
  *) wd_s=$((wd_us / 1000000)) ;;
esac
[ -z "$wd_s" ] && wd_s=60
while :; do
  now_us=$(awk '{ printf "%d", $1 * 1000000 }' /proc/uptime)
  [ $(( (now_us - ready_us) / 1000000 )) -gt $((wd_s + 10)) ] && break
  sleep 2
done
n0=$(prop $unit NRestarts)
[ "$(systemctl is-active $unit)" = active ] && [ "$n0" = "$r_ready" ] \
  && ok "watchdog-pinged active_s=$(( (now_us - ready_us) / 1000000 )) watchdog_s=$wd_s restarts=$n0" \
  || { bad "watchdog-pinged state=$(systemctl is-active $unit) restarts=$n0 (killed by its own watchdog?)"
       dump_journal $unit 20; }

# --- service watchdog: a hung admin rank (SIGSTOP) is killed (WatchdogSec) and the farm restarted --
rank0=""
for p in $(pgrep -x mogao-farm); do [ "$(proc_env "$p" OMPI_COMM_WORLD_RANK)" = 0 ] && rank0=$p; done
main=$(prop $unit MainPID)
if [ -n "$rank0" ]; then
  t0=$(awk '{ print $1 }' /proc/uptime)
  kill -STOP "$rank0"
  say "rank0-stopped pid=$rank0 main=$main restarts=$n0 uptime=$t0"
  i=0 n=$n0 p=$main
  while [ $i -lt 1200 ]; do
    sleep 0.5; i=$((i + 1))
    n=$(prop $unit NRestarts); p=$(prop $unit MainPID)
    [ "$n" -gt "$n0" ] && [ "$p" != "$main" ] && [ "$(systemctl is-active $unit)" = active ] && break
  done
  t1=$(awk '{ print $1 }' /proc/uptime)
  why=$(journal $unit | grep -m1 -i "watchdog timeout")
  kill_t=$(journalctl -b -u $unit -o short-monotonic --no-pager 2>/dev/null | grep -m1 -i "watchdog timeout" |
    sed -E 's/^\[ *([0-9.]+)\].*/\1/')
  if [ "$n" -gt "$n0" ] && [ "$p" != "$main" ] && [ "$(systemctl is-active $unit)" = active ]; then
    ok "watchdog-restart seconds=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }')" \
       "kill_after_s=$(awk -v a="$t0" -v b="${kill_t:-0}" 'BEGIN { printf "%.1f", b - a }')" \
       "new_pid=$p restarts=$n reason='$why'"
  else
    bad "watchdog-restart (restarts=$n pid=$p state=$(systemctl is-active $unit) reason='$why')"
    dump_journal $unit 30
  fi
else
  bad "watchdog-restart (no rank 0 process among: $(ranks))"
fi
say "watchdog-done"
# The farm's journal from now on, for the host (farm_qemu_test.py --host-loss times a lost render
# host's way out of the job and back in by these lines).
journalctl -f -n 0 -u $unit -o cat 2>/dev/null |
  grep --line-buffered -E 'serving |did not reply|render host|left out|asking|answer' |
  while IFS= read -r line; do say "follow $line"; done &
answer=$(host_wait 1800); say "host said '$answer'"
check_common
dump_journal $unit 15
say "done fails=$fails uptime=$(uptime_s)"
exit 0
