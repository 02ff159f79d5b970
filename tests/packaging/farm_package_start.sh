# SPDX-License-Identifier: Apache-2.0
# Sourced by farm_package_test.sh (bash; expects root, work, log, fail, pid_nspawn): the two ways of
# starting the installed farm. Both check that it reaches READY and listens on MOGAO_LISTEN's port.

# The example farm.env listens on [::]:7443; the test moves it to a port of its own (the host's
# network is shared with the root, and other tests may serve on 7443).
farm_port=$((20000 + RANDOM % 20000))
nspawn_reason=""

leader=""

in_container() { nsenter --target "$leader" --all /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root "$@"; }

# container_init: the container's systemd as seen from here: the descendant of systemd-nspawn whose
# PID in its own namespace is 1 (nspawn may or may not fork between itself and it).
container_init() {
  local pid queue=("$pid_nspawn")
  while ((${#queue[@]} > 0)); do
    pid=${queue[0]}
    queue=("${queue[@]:1}")
    if [[ "$pid" != "$pid_nspawn" && "$(awk '/^NSpid:/ { print $NF }' /proc/"$pid"/status 2> /dev/null)" == 1 ]]; then
      echo "$pid"
      return 0
    fi
    queue+=($(cat /proc/"$pid"/task/*/children 2> /dev/null))
  done
}

# boot_under_systemd: boots the root with systemd-nspawn (host network) and checks that the
# enabled farm did not start without its TLS files. Returns 1 with nspawn_reason set when the
# container cannot boot here.
boot_under_systemd() {
  command -v systemd-nspawn > /dev/null || { nspawn_reason="systemd-nspawn not installed"; return 1; }
  # --keep-unit --register=no: no host systemd or D-Bus needed (a build container has neither).
  systemd-nspawn --quiet --directory="$root" --register=no --keep-unit --boot --console=pipe \
    < /dev/null > "$work/nspawn.log" 2>&1 &
  pid_nspawn=$!
  local state="" i
  for ((i = 0; i < 90; i++)); do
    kill -0 "$pid_nspawn" 2> /dev/null || break
    leader=$(container_init)
    if [[ -n "$leader" ]]; then
      state=$(timeout 10 nsenter --target "$leader" --all /usr/bin/env -i PATH=/usr/bin:/bin \
        systemctl is-system-running 2> /dev/null || true)
      [[ "$state" == running || "$state" == degraded ]] && break
    fi
    sleep 1
  done
  if [[ "$state" != running && "$state" != degraded ]]; then
    nspawn_reason="systemd-nspawn --boot: system state '${state:-none}' after ${i} s;"
    nspawn_reason+=" $(grep -v '^$' "$work/nspawn.log" | tail -n 3 | tr '\n' ' ' | cut -c1-300)"
    kill "$pid_nspawn" 2> /dev/null; wait "$pid_nspawn" 2> /dev/null; pid_nspawn=""
    return 1
  fi
  log "container booted in ${i} s (systemd: $state)"
  in_container systemctl is-enabled mogao-farm | grep -qx enabled \
    || fail "mogao-farm.service not enabled in the booted root"
  local active cond
  active=$(in_container systemctl show -P ActiveState mogao-farm)
  cond=$(in_container systemctl show -P ConditionResult mogao-farm)
  [[ "$active" == inactive && "$cond" == no ]] \
    || fail "unconfigured farm at boot: ActiveState=$active ConditionResult=$cond (want inactive, condition not met)"
  log "ok: at boot the enabled, unconfigured farm was not started (ConditionDirectoryNotEmpty=/etc/mogao/pki)"
}

# wait_state WANT...: mogao-farm's ActiveState once it is one of WANT (180 s at most).
wait_state() {
  local state="" i
  for ((i = 0; i < 180; i++)); do
    state=$(in_container systemctl show -P ActiveState mogao-farm)
    [[ " $* " == *" $state "* ]] && break
    sleep 1
  done
  echo "$state"
}

# start_under_systemd: the README's `systemctl enable --now mogao-farm`: active (Type=notify: READY=1
# received) and listening.
start_under_systemd() {
  local t state
  t=$(date +%s)
  in_container systemctl enable --now mogao-farm || true
  state=$(wait_state active failed)
  in_container journalctl -u mogao-farm --no-pager > "$work/farm-journal.txt" 2>&1 || true
  [[ "$state" == active ]] \
    || { tail -n 30 "$work/farm-journal.txt"; fail "mogao-farm.service $state, not active (READY)"; }
  grep -q ":$(printf '%04X' $farm_port) [0-9A-F:]* 0A " /proc/net/tcp6 /proc/net/tcp \
    || fail "mogao-farm active but nothing listens on $farm_port"
  local modes
  modes=$(root_stat "$root"/etc/mogao/pki "$root"/etc/mogao/pki/*)
  grep -qv ' root:mogao-farm \(750\|640\)$' <<<"$modes" && fail "TLS folder not root:mogao-farm 0750/0640: $modes"
  log "ok: systemctl enable --now mogao-farm: active (READY) in $(($(date +%s) - t)) s, listening on $farm_port;" \
    "TLS folder root:mogao-farm 0750/0640"
}

# configuration_error_under_systemd: a bad farm.env (MOGAO_RANKS=0) ends the start with exit 2:
# failed, not restarted, and the journal says why and what to do.
configuration_error_under_systemd() {
  cp "$root/etc/mogao/farm.env" "$work/farm.env.good"
  sed -i 's/^MOGAO_RANKS=.*/MOGAO_RANKS=0/' "$root/etc/mogao/farm.env"
  in_container systemctl restart mogao-farm || true
  local state restarts
  state=$(wait_state failed)
  sleep 2  # a restart would come 500 ms later
  state=$(in_container systemctl show -P ActiveState mogao-farm)
  restarts=$(in_container systemctl show -P NRestarts mogao-farm)
  in_container journalctl -u mogao-farm --no-pager > "$work/farm-journal.txt" 2>&1 || true
  [[ "$state" == failed && "$restarts" == 0 ]] \
    || fail "farm with MOGAO_RANKS=0: $state after $restarts restarts (want failed, 0)"
  grep -q "configuration error (exit 2, named above): not restarted" "$work/farm-journal.txt" \
    || { tail -n 20 "$work/farm-journal.txt"; fail "no journal line for the configuration error"; }
  grep -q "RANKS must be a number >= 1" "$work/farm-journal.txt" || fail "the journal does not name MOGAO_RANKS"
  cp "$work/farm.env.good" "$root/etc/mogao/farm.env"
  log "ok: MOGAO_RANKS=0: failed with exit 2, not restarted, the journal names the field and says so"
}

# write_client_script: /root/link-client.sh in the root, the link client's commands, run there while
# the farm serves: an appliance certificate from the README's CA, a kiosk configuration
# (kiosk.example.toml with overrides: headless outputs, the ideal 3-projector calibration at 320x240)
# and the kiosk until 10 of the farm's frames are on its screen (statistics in /root/kiosk-stats.json).
write_client_script() {
  cat > "$root/root/link-client.sh" << EOF
set -e
mogao-farm pki issue-appliance --dir /root/mogao-ca --name museum-1
mogao-kiosk --print-config 'farm.endpoint="[::1]:$farm_port"' 'farm.ca="/root/mogao-ca/ca.pem"' \\
  'farm.cert="/root/mogao-ca/appliance-museum-1.pem"' 'farm.key="/root/mogao-ca/appliance-museum-1.key"' \\
  'outputs.backend="headless"' 'calibration.source="ideal"' 'calibration.projectors=3' \\
  'calibration.overlap=0.15' 'calibration.output="320x240"' 'quality.content="480x270"' 'quality.spp=1' \\
  'navigation.start=[0.0, 0.0, 4.0]' 'stats.file=' > /root/kiosk.toml
exec timeout 240 mogao-kiosk --config /root/kiosk.toml --frames 10 --duration-s 200 --stats /root/kiosk-stats.json
EOF
}

# serve_frames RUNNER...: the link client through RUNNER against the farm systemd started, then the
# checks of check_served_frames.
serve_frames() {
  write_client_script
  "$@" sh /root/link-client.sh > "$work/kiosk.log" 2>&1 \
    || { tail -n 30 "$work/kiosk.log"; fail "the link client (mogao-kiosk) failed"; }
  check_served_frames
}

# check_served_frames: the kiosk showed 10 farm frames (none rejected, exit 0), and the farm's
# metrics file, written by the mogao-farm user into node_exporter's folder (mode 0644, readable by
# the exporter's user), counts at least as many frames sent (rewritten about once a second).
check_served_frames() {
  local stats="$root/root/kiosk-stats.json" prom="$root/var/lib/prometheus/node-exporter/mogao-farm.prom"
  local shown sent="" i
  [[ -f "$stats" ]] || fail "the link client wrote no statistics"
  shown=$(python3 -c 'import json, sys; s = json.load(open(sys.argv[1]))
print(s["frames_presented"] if s["exit_code"] == 0 and s["frames_rejected"] == 0 else -1)' "$stats")
  ((shown >= 10)) \
    || fail "the link client: $shown frames presented (want >= 10, none rejected, exit 0): $(head -c 400 "$stats")"
  for ((i = 0; i < 10; i++)); do
    sent=$(awk '$1 == "mogao_farm_frames_sent_total" { print $2 }' "$prom" 2> /dev/null || true)
    [[ -n "$sent" ]] && ((${sent%.*} >= shown)) && break
    sleep 1
  done
  [[ -f "$prom" ]] || fail "no metrics file $prom (the farm user cannot write node_exporter's folder?)"
  [[ "$(root_stat "$prom")" == *" mogao-farm:mogao-farm 644" ]] \
    || fail "metrics file $(root_stat "$prom"), want mogao-farm:mogao-farm 0644"
  [[ -n "$sent" ]] && ((${sent%.*} >= shown)) \
    || fail "mogao_farm_frames_sent_total ${sent:-missing} < $shown frames the client showed"
  log "ok: served frames: the kiosk showed $shown farm frames; $(basename "$prom") in node_exporter's folder" \
    "(mogao-farm, 0644): mogao_farm_frames_sent_total $sent"
}

stop_container() {
  in_container systemctl poweroff > /dev/null 2>&1 || true
  wait "$pid_nspawn" 2> /dev/null || true
  pid_nspawn=""
}

# start_as_the_unit_does: the installed unit's ExecStartPre and ExecStart run as systemd would run
# them, in a chroot (tests/packaging/unit_start.py; the sandbox settings are not reproduced), and
# the link client while it serves.
start_as_the_unit_does() {
  local unit=/lib/systemd/system/mogao-farm.service
  [[ -d "$root/etc/mogao/pki" ]] && [[ -n "$(ls -A "$root/etc/mogao/pki")" ]] \
    || fail "ConditionDirectoryNotEmpty=/etc/mogao/pki would not let the unit start"
  write_client_script
  unshare --mount --propagation private -- /bin/sh -c '
    r=$1; shift
    mount -t proc proc "$r/proc" && mount -t sysfs sys "$r/sys" && mount --rbind /dev "$r/dev" || exit 1
    mount -t tmpfs -o mode=1777 tmp "$r/tmp" && mount -t tmpfs -o mode=0755 run "$r/run" || exit 1
    exec python3 "$@"' sh "$root" "$(dirname "${BASH_SOURCE[0]}")/unit_start.py" "$root" "$unit" "$farm_port" 180 \
    sh /root/link-client.sh \
    | tee "$work/unit-start.log" || fail "the farm did not start as its unit runs it (log above)"
  # The ExecStartPre (tmpfiles.d/mogao-farm-pki.conf) made the TLS folder readable by the farm only.
  local modes
  modes=$(root_stat "$root"/etc/mogao/pki "$root"/etc/mogao/pki/*)
  grep -qv ' root:mogao-farm \(750\|640\)$' <<<"$modes" && fail "TLS folder not root:mogao-farm 0750/0640: $modes"
  log "ok: READY and listening on $farm_port; TLS folder root:mogao-farm 0750, files 0640"
}
