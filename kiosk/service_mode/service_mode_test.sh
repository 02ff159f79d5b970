#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# service_mode_requests test: the appliance's request check (mogao-service verify) on requests made
# by the museum's tool (mogao-service-request), on this host with real OpenSSL Ed25519 keys; no
# appliance needed (the QEMU test image_qemu_service_mode runs the whole mode in the image).
#   service_mode_test.sh SERVICE_MODE_DIR
# Accepted: a signed request, once. Refused, each with its reason and the serial state unchanged:
# a replay, an older serial, a changed byte, another museum's key, no signature, an expired request,
# one valid too long, an unknown field, a malformed line, captures changed after signing.
set -uo pipefail
dir=$1
command -v openssl > /dev/null || { echo "SKIP: openssl not installed"; exit 77; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export MOGAO_SERVICE_KEY=$work/museum/service-key.pem MOGAO_SERVICE_STATE=$work/state MOGAO_SERVICE_WALL=
req=$dir/mogao-service-request svc=$dir/mogao-service
fail=0
"$req" keygen --out "$work/museum" > /dev/null
"$req" keygen --out "$work/other" > /dev/null
key=$work/museum/service-signing.key

sign() { # sign NAME SERIAL [ARGS...]: a signed stick folder
  local name=$1 serial=$2; shift 2
  mkdir -p "$work/$name"
  "$req" sign --key "$key" --action logs --stick "$work/$name" --serial "$serial" "$@" > /dev/null
}
accepts() { # accepts NAME WHAT
  if out=$("$svc" verify "$work/$1" 2>&1); then echo "ok: accepted $2"; else echo "FAIL: refused $2: $out"; fail=1; fi
}
refuses() { # refuses NAME REASON-PATTERN WHAT
  local before out
  before=$(cat "$work/state/last-serial" 2> /dev/null)
  if out=$("$svc" verify "$work/$1" 2>&1); then
    echo "FAIL: accepted $3"; fail=1
  elif ! grep -q -- "$2" <<< "$out"; then
    echo "FAIL: $3 refused, but not for '$2': $out"; fail=1
  elif [[ "$(cat "$work/state/last-serial" 2> /dev/null)" != "$before" ]]; then
    echo "FAIL: $3 refused, but the serial state changed"; fail=1
  else
    echo "ok: refused $3 ($(grep -m1 -o 'REFUSED: .*' <<< "$out" | cut -c10-90))"
  fi
}

sign good 100
accepts good "a signed request"
refuses good "used already" "the same request again (replay)"
sign older 99
refuses older "used already" "an older serial"
sign changed 101
sed -i 's/action = "logs"/action = "calibrate"/' "$work/changed/request.toml"
refuses changed "bad signature" "a request changed after signing"
mkdir -p "$work/foreign"
"$req" sign --key "$work/other/service-signing.key" --action logs --stick "$work/foreign" --serial 102 > /dev/null
refuses foreign "bad signature" "another museum's key"
sign unsigned 103
rm "$work/unsigned/request.toml.sig"
refuses unsigned "not signed" "a request without signature"
# Expired / too long / unknown field / bad line: re-signed after the edit, so only the content is judged.
resign() { openssl pkeyutl -sign -inkey "$key" -rawin -in "$work/$1/request.toml" -out "$work/$1/request.toml.sig"; }
sign expired 104
sed -i "s/^not_after = .*/not_after = \"$(date -u -d '-1 hour' +%Y-%m-%dT%H:%M:%SZ)\"/" "$work/expired/request.toml";
    resign expired
refuses expired "expired" "an expired request"
sign long 105
sed -i "s/^not_after = .*/not_after = \"$(date -u -d '+40 days' +%Y-%m-%dT%H:%M:%SZ)\"/" "$work/long/request.toml";
    resign long
refuses long "more than 31 days" "a request valid for 40 days"
sign unknown 106
echo 'command = "rm"' >> "$work/unknown/request.toml"; resign unknown
refuses unknown "unknown field 'command'" "an unknown field"
sign badline 107
echo 'action = $(reboot)' >> "$work/badline/request.toml"; resign badline
refuses badline "line 7: not a" "a line that is not key = value"
mkdir -p "$work/cap/captures"
echo one > "$work/cap/captures/a.png"
"$req" sign --key "$key" --action calibrate --stick "$work/cap" --serial 108 --captures captures > /dev/null
echo two > "$work/cap/captures/a.png"
refuses cap "not the ones signed" "captures changed after signing"
sign fresh 109
accepts fresh "a new serial after the refusals"
"$svc" bogus > /dev/null 2>&1; [[ $? == 2 ]] && echo "ok: usage error exits 2" || { echo "FAIL: usage exit"; fail=1; }
exit $fail
