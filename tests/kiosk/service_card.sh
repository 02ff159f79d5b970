#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Appliance liveness: a missing or corrupt configuration partition must not leave the
# projectors dark in a restart loop. mogao-kiosk with neither its configuration nor a last good
# copy shows the service card ("SERVICE NEEDED" and the reason) on every output, stays up (READY,
# watchdog fed: kiosk/display/service_screen.h), and exits 1 for systemd to start the show once the
# configuration loads again.
#   missing   --config names a file that does not exist (an unmounted partition): card on both
#             outputs (headless, two sizes), exit 0 at --duration-s
#   corrupt   not TOML: card; then a good configuration is written: exit 1 within the retry
# The outputs come from --service-config (headless here; the appliance uses the built-in KMS).
#
# usage: service_card.sh FARM KIOSK IMAGE_TOOL MPIEXEC SOURCE_DIR WORK_DIR
farm=$1 kiosk=$2 tool=$3 MPIEXEC=$4 src=$5 work=$6
source "$src/tests/kiosk/kiosk_e2e_common.sh"
rm -rf "$work"
mkdir -p "$work"
export MOGAO_LAST_GOOD_DIR="$work/last-good"   # empty: no last good copy to fall back on

printf '[outputs]\nbackend = "headless"\nsizes = ["800x600", "640x480"]\npng_dir = "%s"\n' "$work/png" > \
    "$work/service.toml"

# missing: the card on both outputs, the process up until --duration-s.
timeout 60 "$kiosk" --config "$work/absent/kiosk.toml" --service-config "$work/service.toml" --duration-s 2 \
  > "$work/missing.log" 2>&1
rc=$?
cat "$work/missing.log"
(( rc == 0 )) || fail "missing: exit $rc, expected 0 (the card until --duration-s)"
grep -q "service card on every output: .*absent/kiosk.toml: no such file" "$work/missing.log" ||
  fail "missing: the log does not name the file and the reason"
cards=("$work"/png/headless-0-*.png "$work"/png/headless-1-*.png)
[[ -f "${cards[0]}" && -f "${cards[1]}" ]] || fail "missing: no card PNG for both outputs (${cards[*]})"
"$tool" stats "${cards[@]}" > "$work/stats.txt" || fail "missing: a card PNG is unreadable"
cat "$work/stats.txt"
python3 - "$work/stats.txt" <<'PY' || fail "missing: see above"
import sys
rows = [l.split() for l in open(sys.argv[1])]
sizes = sorted((int(w), int(h)) for _, w, h, _, _ in rows)
assert sizes == [(640, 480), (800, 600)], f"FAIL: output sizes {sizes}"
for name, w, h, mean, dark in rows:
    # The card: dim background (codes 20-60) with light text; a dark output would be ~0.
    assert float(mean) > 15, f"FAIL: {name} is dark (mean {mean})"
PY

# corrupt, then repaired: exit 1 so that systemd starts the show.
make_pki "$work/pki" "::1"
printf 'this is [not TOML\n' > "$work/kiosk.toml"
timeout 60 "$kiosk" --config "$work/kiosk.toml" --service-config "$work/service.toml" --duration-s 40 \
  > "$work/corrupt.log" 2>&1 &
kiosk_pid=$!
for _ in $(seq 100); do grep -q "service card on every output" "$work/corrupt.log" && break; sleep 0.1; done
grep -q "service card on every output: .*kiosk.toml.*not valid TOML" "$work/corrupt.log" ||
  { cat "$work/corrupt.log"; fail "corrupt: no service card naming the file"; }
write_config "$work/kiosk.toml.new" "[::1]:7443" "$work/pki" "$work/png-show" 10
mv "$work/kiosk.toml.new" "$work/kiosk.toml"
start=$SECONDS
wait "$kiosk_pid"
rc=$?
kiosk_pid=""
cat "$work/corrupt.log"
(( rc == 1 )) || fail "corrupt: exit $rc after the repair, expected 1 (for systemd to start the show)"
(( SECONDS - start <= 15 )) || fail "corrupt: the repair took $((SECONDS - start)) s to be noticed"
grep -q "loads again" "$work/corrupt.log" || fail "corrupt: the log does not say the configuration loads again"
log "PASS"
