#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# image_scripts test: the image scripts parse, and their --help works (no root, no network).
set -eu
dir=$1
bash -n "$dir/build"
bash -n "$dir/provision"
bash -n "$dir/lib/common.sh"
bash -n "$dir/test/image_tests.sh"
bash -n "$dir/test/build_vimc.sh"
sh -n "$dir/test/selftest.sh"
bash -n "$dir/test/powercut_guest.sh"
python3 - "$dir/test/qemu_boot_test.py" "$dir/test/qemu_service_card_test.py" "$dir/test/qemu_common.py" "$dir/test/qemu_libcamera.py" "$dir/lib/prune_modules.py" "$dir/test/qemu_powercut_test.py" "$dir/test/powercut_report.py" "$dir/test/qemu_service_mode_test.py" <<'PY'
import sys
for f in sys.argv[1:]:
    compile(open(f).read(), f, "exec")
PY
# The power-cut verdict (qemu_powercut_test.classify) on made-up states: old, new, torn, missing, mixed.
python3 - "$dir/test" <<'PY'
import sys
sys.path.insert(0, sys.argv[1])
from qemu_powercut_test import classify
old = {"etc/screen.mpcdi": ("a", 1), "etc/screen.models.json": ("b", 1)}
new = {"etc/screen.mpcdi": ("c", 1), "etc/screen.models.json": ("d", 1), "etc/screen.mpcdi.last-good": ("a", 1)}
assert classify("calibrate", old, new, dict(old), []) == ("before", [])
assert classify("calibrate", old, new, dict(new), []) == ("after", [])
assert classify("calibrate", old, new, dict(old), [".screen.mpcdi.tmp-x"])[0] == "during"
torn = dict(new, **{"etc/screen.mpcdi": ("e", 1)})
assert "torn" in classify("calibrate", old, new, torn, [])[1][0]
gone = {k: v for k, v in new.items() if k != "etc/screen.mpcdi"}
assert "missing" in classify("calibrate", old, new, gone, [])[1][0]
mixed = dict(old, **{"etc/screen.models.json": ("d", 1)})
assert any(p.startswith("mixed") for p in classify("calibrate", old, new, mixed, [])[1])
PY
"$dir/build" --help | grep -q "image/build"
"$dir/provision" --help | grep -q "image/provision"
# The fstab labels are the ones image/build and image/provision write.
source "$dir/lib/common.sh"
grep -q "^LABEL=$MOGAO_ROOT_LABEL " "$dir/rootfs/etc/fstab"
grep -q "^LABEL=$MOGAO_CONFIG_LABEL " "$dir/rootfs/etc/fstab"
grep -q "^u mogao-kiosk $MOGAO_KIOSK_UID:$MOGAO_KIOSK_GID " "$dir/rootfs/usr/lib/sysusers.d/mogao.conf"
# provision refuses a configuration folder holding a CA's private key, by name and by content,
# before it needs root or an image.
farm=${2:-}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/cfg/pki"
touch "$tmp/cfg/kiosk.toml" "$tmp/cfg/pki/ca.key"
out=$("$dir/provision" "$tmp/none.img" "$tmp/cfg" 2>&1) && { echo "provision accepted ca.key"; exit 1; }
grep -q "ca.key: a CA or farm private key" <<< "$out" || { echo "provision: unexpected message: $out"; exit 1; }
if [[ -n "$farm" && -x "$farm" ]]; then
  "$farm" pki init-ca --dir "$tmp/ca" > /dev/null
  rm "$tmp/cfg/pki/ca.key"
  cp "$tmp/ca/ca.pem" "$tmp/cfg/pki/ca.pem"
  cp "$tmp/ca/ca.key" "$tmp/cfg/pki/appliance-museum-1.key"   # the CA key under an innocent name
  out=$("$dir/provision" "$tmp/none.img" "$tmp/cfg" 2>&1) && { echo "provision accepted a renamed CA key"; exit 1; }
  grep -q "appliance-museum-1.key: this is a CA's private key" <<< "$out" || { echo "provision: unexpected message: $out"; exit 1; }
fi
# provision derives the kiosk's network allow-list from kiosk.toml's farm endpoint and refuses a
# name or a bad --allow, before it needs root or an image.
rm -f "$tmp/cfg/pki/"*.key
printf '[farm]\nendpoint = "farm.example:7443"\n' > "$tmp/cfg/kiosk.toml"
out=$("$dir/provision" "$tmp/none.img" "$tmp/cfg" 2>&1) && { echo "provision accepted a farm name"; exit 1; }
grep -q 'endpoint .farm.example:7443. is not "\[address\]:port"' <<< "$out" || { echo "provision: unexpected message: $out"; exit 1; }
printf '[farm]\nendpoint = "[2001:db8::7]:7443"\n' > "$tmp/cfg/kiosk.toml"
out=$("$dir/provision" --allow 10.1.0.0/16 --allow not-an-address "$tmp/none.img" "$tmp/cfg" 2>&1) && { echo "provision accepted --allow not-an-address"; exit 1; }
grep -q "allow 'not-an-address' is not an IP address or prefix" <<< "$out" || { echo "provision: unexpected message: $out"; exit 1; }
# provision takes the service mode's public key only (docs/service-mode.md): a private key and a
# key of another type are refused, before it needs root or an image.
if command -v openssl > /dev/null; then
  openssl genpkey -algorithm ed25519 -out "$tmp/cfg/service-key.pem" 2> /dev/null
  out=$("$dir/provision" "$tmp/none.img" "$tmp/cfg" 2>&1) && { echo "provision accepted a private service key"; exit 1; }
  grep -q "service-key.pem: a private key" <<< "$out" || { echo "provision: unexpected message: $out"; exit 1; }
  openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 2> /dev/null | openssl pkey -pubout -out "$tmp/cfg/service-key.pem"
  out=$("$dir/provision" "$tmp/none.img" "$tmp/cfg" 2>&1) && { echo "provision accepted an EC service key"; exit 1; }
  grep -q "service-key.pem: not an Ed25519 public key" <<< "$out" || { echo "provision: unexpected message: $out"; exit 1; }
  rm "$tmp/cfg/service-key.pem"
fi
bash -n "$dir/../kiosk/service_mode/mogao-service"
bash -n "$dir/../kiosk/service_mode/mogao-service-request"
# kiosk-ip-allow turns farm-addresses into runtime IPAddressAllow properties (systemctl stand-in),
# and refuses a missing file, an empty list and a line that is not an address, naming the line.
mkdir -p "$tmp/bin"
printf '#!/bin/sh\necho "$@" > "%s/systemctl.args"\n' "$tmp" > "$tmp/bin/systemctl"
chmod +x "$tmp/bin/systemctl"
allow=$dir/rootfs/usr/lib/mogao/kiosk-ip-allow
printf '# comment\n2001:db8::7\n\n10.1.0.0/16  # lab\n' > "$tmp/addrs"
PATH="$tmp/bin:$PATH" "$allow" "$tmp/addrs" > /dev/null
[[ $(cat "$tmp/systemctl.args") == "set-property --runtime mogao-kiosk.service IPAddressAllow=2001:db8::7 IPAddressAllow=10.1.0.0/16" ]] \
  || { echo "kiosk-ip-allow: unexpected systemctl call: $(cat "$tmp/systemctl.args")"; exit 1; }
rm -f "$tmp/systemctl.args"
printf '2001:db8::7\nfarm.example\n' > "$tmp/addrs"
out=$(PATH="$tmp/bin:$PATH" "$allow" "$tmp/addrs" 2>&1) && { echo "kiosk-ip-allow accepted a name"; exit 1; }
grep -q "addrs:2: 'farm.example' is not an IP address" <<< "$out" || { echo "kiosk-ip-allow: unexpected message: $out"; exit 1; }
printf '# nothing\n' > "$tmp/addrs"
PATH="$tmp/bin:$PATH" "$allow" "$tmp/addrs" 2> /dev/null && { echo "kiosk-ip-allow accepted an empty list"; exit 1; }
PATH="$tmp/bin:$PATH" "$allow" "$tmp/missing" 2> /dev/null && { echo "kiosk-ip-allow accepted a missing file"; exit 1; }
[[ ! -e "$tmp/systemctl.args" ]] || { echo "kiosk-ip-allow called systemctl on bad input"; exit 1; }
echo "image scripts: ok"
