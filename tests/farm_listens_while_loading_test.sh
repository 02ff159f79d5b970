#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# `mogao-farm serve` listens from before its scene loads (renderfarm/farm/serve.h, ServeLink), so an
# appliance reconnecting to a restarted farm overlaps the load instead of following it. The scene
# file is a named pipe: the load blocks in open() until the test writes the scene, so the test knows
# the farm is loading while it connects. Then a scene that loads ends in serving; one that does not
# ends the job with exit 1 and the listening link closed, not a hang.
set -uo pipefail
farm=$1 MPIEXEC=$2 work=$3
source "$(dirname "$0")/mpi_env.sh"
rm -rf "$work" && mkdir -p "$work"
fail=0
"$farm" pki init-ca --dir "$work/pki" > /dev/null && "$farm" pki issue-farm --dir "$work/pki" --name farm \
    --san ::1 > /dev/null \
  && "$farm" pki export-farm --dir "$work/pki" --name farm --to "$work/farm-tls" > /dev/null ||
  { echo "FAIL: pki"; exit 1; }
free_port() {
  python3 -c 'import socket; s = socket.socket(socket.AF_INET6); s.bind(("::1", 0)); print(s.getsockname()[1])'
}
accepts() {
  python3 -c 'import socket, sys; socket.create_connection(("::1", int(sys.argv[1])), timeout=1).close()' "$1" \
    2> /dev/null
}
# The admin's line once the scene is loaded (serve.cpp), as the other tests and benches wait for it.
serving() { grep -q 'render ranks, .*) on ' "$1"; }

# case NAME SCENE_TEXT EXPECTED_RC LOG_FRAGMENT: starts the farm on a pipe, checks it accepts while loading.
case_run() {
  local name=$1 scene=$2 expected=$3 fragment=$4 port
  port=$(free_port)
  mkfifo "$work/$name.json"
  timeout 120 "$MPIEXEC" --oversubscribe -n 1 "$farm" serve --scene "$work/$name.json" --listen "[::1]:$port" \
    --name farm --tls-dir "$work/farm-tls" --duration-s 2 > "$work/$name.log" 2>&1 &
  local pid=$! listening=0
  for _ in $(seq 1 200); do
    if accepts "$port"; then listening=1; break; fi
    kill -0 $pid 2> /dev/null || break
    sleep 0.1
  done
  if serving "$work/$name.log"; then
    echo "FAIL: $name: the farm logged 'serving' before its scene was written"; fail=1
  elif [ $listening -eq 1 ]; then
    echo "ok: $name: [::1]:$port accepts connections while the scene loads"
  else
    echo "FAIL: $name: [::1]:$port did not accept a connection within 20 s of the start, the scene unread"; fail=1
  fi
  # A farm that died before it opened the pipe would leave this write waiting for a reader.
  timeout 20 bash -c 'printf "%s" "$1" > "$2"' _ "$scene" "$work/$name.json" ||
    { echo "FAIL: $name: nothing read the scene within 20 s"; fail=1; }
  wait $pid
  local rc=$?
  if [ $rc -ne "$expected" ]; then
    echo "FAIL: $name: exit $rc, expected $expected (124: the job did not end)"; cat "$work/$name.log"; fail=1
  elif ! grep -q -- "$fragment" "$work/$name.log"; then
    echo "FAIL: $name: log lacks '$fragment'"; cat "$work/$name.log"; fail=1
  else
    echo "ok: $name: exit $rc, $(grep -m1 -- "$fragment" "$work/$name.log")"
  fi
}
case_run loads '{ "meshes": { "m": { "procedural": "box", "size": [1, 1, 1] } }, "objects": [ { "mesh": "m" } ] }' \
  0 "render ranks, "
case_run fails '{ "meshes": ' 1 "not valid JSON"
[ $fail -eq 0 ] && echo "PASS: the farm listens while its scene loads"
exit $fail
