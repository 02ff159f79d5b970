#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# End to end, farm -> appliance over real IPv6 with mutual TLS:
#   netns     the farm (3 MPI ranks) in network namespace A at fd00:6d6f::1, the kiosk (headless,
#             ideal 3-projector calibration) in namespace B at fd00:6d6f::2, joined by a veth pair
#             with 5 ms netem delay each way; skipped (77) where namespaces are not permitted
#   loopback  the same over [::1] without namespaces
#   multihost the farm on two hosts: its admin (mpirun, ranks 0 and 1) in namespace A and a render
#             host (rank 2) in namespace R, each with its own host name (UTS namespace), joined by a
#             veth pair on 10.77.1.0/24 that Open MPI's TCP transport must use; mpirun reads a host
#             file and starts the remote daemon with an rsh agent that enters R -- a stand-in for
#             the ssh of docs/services.md (the rest is the real Open MPI launch and TCP exchange,
#             with the Open MPI settings of systemd/mogao-farm.service); the kiosk in namespace B
#             reaches A over IPv6. Also checks that a farm rank ran in R.
# Checks: 100 frames delivered and shown, request ids strictly increasing, no frame rejected; each
# dumped content frame within 35 dB PSNR of the farm's lossless render of the same pose (and a
# different pose's render below it); the projector PNGs and the composited screen readable and
# not black. Latency, fps and bandwidth go to the test log.
#
# usage: e2e_netns.sh netns|loopback|multihost FARM KIOSK IMAGE_TOOL MPIEXEC SOURCE_DIR WORK_DIR
mode=$1 farm=$2 kiosk=$3 tool=$4 MPIEXEC=$5 src=$6 work=$7
source "$src/tests/kiosk/kiosk_e2e_common.sh"

rm -rf "$work"
mkdir -p "$work"
farm_prefix=()
kiosk_prefix=()
if [[ "$mode" == netns || "$mode" == multihost ]]; then
  ns_farm="mogao-farm-$$"
  ns_kiosk="mogao-kiosk-$$"
  netns_add_or_skip "$ns_farm"
  ip netns add "$ns_kiosk" || fail "ip netns add $ns_kiosk"
  netns_created+=("$ns_kiosk")
  veth_f="mgf$$"
  veth_k="mgk$$"
  ip link add "$veth_f" netns "$ns_farm" type veth peer name "$veth_k" netns "$ns_kiosk" || fail "veth pair"
  ip -n "$ns_farm" link set lo up
  ip -n "$ns_kiosk" link set lo up
  ip -n "$ns_farm" -6 addr add fd00:6d6f::1/64 dev "$veth_f" nodad || fail "address in $ns_farm"
  ip -n "$ns_kiosk" -6 addr add fd00:6d6f::2/64 dev "$veth_k" nodad || fail "address in $ns_kiosk"
  ip -n "$ns_farm" link set "$veth_f" up
  ip -n "$ns_kiosk" link set "$veth_k" up
  if ip netns exec "$ns_farm" tc qdisc add dev "$veth_f" root netem delay 5ms 2>/dev/null &&
     ip netns exec "$ns_kiosk" tc qdisc add dev "$veth_k" root netem delay 5ms 2>/dev/null; then
    log "netem: 5 ms delay each way (10 ms round trip)"
  else
    log "netem unavailable (sch_netem): no added delay"
  fi
  farm_addr="fd00:6d6f::1"
  port=7443
  farm_prefix=(ip netns exec "$ns_farm")
  kiosk_prefix=(ip netns exec "$ns_kiosk")
  if [[ "$mode" == multihost ]]; then
    ns_render="mogao-render-$$"
    ip netns add "$ns_render" || fail "ip netns add $ns_render"
    netns_created+=("$ns_render")
    ip link add "mga$$" netns "$ns_farm" type veth peer name "mgr$$" netns "$ns_render" ||
        fail "veth pair to the render host"
    ip -n "$ns_render" link set lo up
    ip -n "$ns_farm" addr add 10.77.1.1/24 dev "mga$$" || fail "address in $ns_farm"
    ip -n "$ns_render" addr add 10.77.1.2/24 dev "mgr$$" || fail "address in $ns_render"
    ip -n "$ns_farm" link set "mga$$" up
    ip -n "$ns_render" link set "mgr$$" up
    # The rsh agent: "agent HOST COMMAND" runs COMMAND on HOST, here by entering its namespace
    # with its own host name (Open MPI passes the remote command as arguments, like to ssh).
    cat > "$work/rsh-agent" <<AGENT
#!/bin/sh
host=\$1; shift
case \$host in
  10.77.1.1) exec ip netns exec $ns_farm unshare --uts sh -c "hostname farm-admin; \$*" ;;
  10.77.1.2) exec ip netns exec $ns_render unshare --uts sh -c "hostname farm-render2; \$*" ;;
  *) echo "rsh-agent: unknown host \$host" >&2; exit 1 ;;
esac
AGENT
    chmod +x "$work/rsh-agent"
    printf '10.77.1.1 slots=2\n10.77.1.2 slots=1\n' > "$work/farm-hosts"
    # The Open MPI settings of systemd/mogao-farm.service, and the farm network only.
    export OMPI_MCA_pml=ob1 OMPI_MCA_osc=^ucx OMPI_MCA_memory=^patcher
    FARM_MPI_ARGS=(--hostfile "$work/farm-hosts" --mca plm_rsh_agent "$work/rsh-agent"
                   --mca btl self,vader,tcp --mca btl_tcp_if_include 10.77.1.0/24 --mca oob_tcp_if_include 10.77.1.0/24)
    farm_prefix=(ip netns exec "$ns_farm" unshare --uts sh -c 'hostname farm-admin; exec "$@"' farm-admin)
  fi
elif [[ "$mode" == loopback ]]; then
  farm_addr="::1"
  port=$((20000 + $$ % 20000))
else
  fail "mode must be netns or loopback, not '$mode'"
fi
endpoint="[$farm_addr]:$port"
log "farm at $endpoint ($mode)"

make_pki "$work/pki" "$farm_addr"
write_config "$work/kiosk.toml" "$endpoint" "$work/pki" "$work/png" 10
start_farm "$work/farm.log" "$endpoint" "${farm_prefix[@]}"
if [[ "$mode" == multihost ]]; then
  grep -q "(2 render ranks" "$work/farm.log" || { cat "$work/farm.log";
      fail "the farm does not serve with 2 render ranks"; }
  remote=$(for pid in $(ip netns pids "$ns_render"); do cat "/proc/$pid/comm" 2>/dev/null; done | grep -c \
      '^mogao-farm$')
  (( remote == 1 )) || fail \
      "$remote mogao-farm processes on the render host (namespace $ns_render), expected 1 (rank 2)"
  log "rank 2 runs on the render host (namespace $ns_render); ranks 0-1 on the admin"
fi

"${kiosk_prefix[@]}" timeout 300 "$kiosk" --config "$work/kiosk.toml" --frames 100 --duration-s 240 \
  --dump-content "$work/content" --dump-every 25 --stats "$work/stats.json" >"$work/kiosk.log" 2>&1
rc=$?
stop_farm TERM
cat "$work/kiosk.log"
(( rc == 0 )) || fail "mogao-kiosk exited with $rc"
[[ -f "$work/stats.json" ]] || fail "no statistics written"

status=0
check_stats "$work/stats.json" 100 || status=1
check_pngs "$work"/png/*.png || status=1
check_psnr "$work/content" "$work/refs" || status=1
(( status == 0 )) || fail "see above"
log "PASS"
