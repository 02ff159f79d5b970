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
bash -n "$dir/rootfs/usr/lib/mogao/journal-persistent"
py_files=("$dir/test/qemu_boot_test.py" "$dir/test/qemu_service_card_test.py" "$dir/test/qemu_common.py"
          "$dir/test/qemu_qmp.py" "$dir/test/qemu_libcamera.py" "$dir/lib/prune_modules.py"
          "$dir/test/qemu_powercut_test.py" "$dir/test/powercut_report.py" "$dir/test/qemu_service_mode_test.py"
          "$dir/test/qemu_update_test.py")
python3 - "${py_files[@]}" <<'PY'
import sys
for f in sys.argv[1:]:
    compile(open(f).read(), f, "exec")
PY
# The QEMU tests import what they share (qemu_common, qemu_qmp, qemu_boot_test) without error.
python3 - "$dir/test" <<'PY'
import sys
sys.path.insert(0, sys.argv[1])
import qemu_boot_test, qemu_service_card_test, qemu_service_mode_test, qemu_update_test  # noqa: F401,E401
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
# The root is not in fstab: both slots' file systems carry its label (docs/updates.md).
! grep -q "^LABEL=$MOGAO_ROOT_LABEL " "$dir/rootfs/etc/fstab"
grep -q "^PARTLABEL=ESP  *\/efi  *vfat .*x-systemd.automount" "$dir/rootfs/etc/fstab"
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
  grep -q "appliance-museum-1.key: this is a CA's private key" <<< "$out" ||
      { echo "provision: unexpected message: $out"; exit 1; }
fi
# provision derives the kiosk's network allow-list from kiosk.toml's farm endpoint and refuses a
# name or a bad --allow, before it needs root or an image.
rm -f "$tmp/cfg/pki/"*.key
printf '[farm]\nendpoint = "farm.example:7443"\n' > "$tmp/cfg/kiosk.toml"
out=$("$dir/provision" "$tmp/none.img" "$tmp/cfg" 2>&1) && { echo "provision accepted a farm name"; exit 1; }
grep -q 'endpoint .farm.example:7443. is not "\[address\]:port"' <<< "$out" ||
    { echo "provision: unexpected message: $out"; exit 1; }
printf '[farm]\nendpoint = "[2001:db8::7]:7443"\n' > "$tmp/cfg/kiosk.toml"
out=$("$dir/provision" --allow 10.1.0.0/16 --allow not-an-address "$tmp/none.img" "$tmp/cfg" 2>&1) &&
    { echo "provision accepted --allow not-an-address"; exit 1; }
grep -q "allow 'not-an-address' is not an IP address or prefix" <<< "$out" ||
    { echo "provision: unexpected message: $out"; exit 1; }
# provision takes the service mode's public key only (docs/service-mode.md): a private key and a
# key of another type are refused, before it needs root or an image.
if command -v openssl > /dev/null; then
  openssl genpkey -algorithm ed25519 -out "$tmp/cfg/service-key.pem" 2> /dev/null
  out=$("$dir/provision" "$tmp/none.img" "$tmp/cfg" 2>&1) &&
      { echo "provision accepted a private service key"; exit 1; }
  grep -q "service-key.pem: a private key" <<< "$out" || { echo "provision: unexpected message: $out"; exit 1; }
  openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 2> /dev/null |
      openssl pkey -pubout -out "$tmp/cfg/service-key.pem"
  out=$("$dir/provision" "$tmp/none.img" "$tmp/cfg" 2>&1) && { echo "provision accepted an EC service key"; exit 1; }
  grep -q "service-key.pem: not an Ed25519 public key" <<< "$out" ||
      { echo "provision: unexpected message: $out"; exit 1; }
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
[[ $(cat "$tmp/systemctl.args") == \
    "set-property --runtime mogao-kiosk.service IPAddressAllow=2001:db8::7 IPAddressAllow=10.1.0.0/16" ]] \
  || { echo "kiosk-ip-allow: unexpected systemctl call: $(cat "$tmp/systemctl.args")"; exit 1; }
rm -f "$tmp/systemctl.args"
printf '2001:db8::7\nfarm.example\n' > "$tmp/addrs"
out=$(PATH="$tmp/bin:$PATH" "$allow" "$tmp/addrs" 2>&1) && { echo "kiosk-ip-allow accepted a name"; exit 1; }
grep -q "addrs:2: 'farm.example' is not an IP address" <<< "$out" ||
    { echo "kiosk-ip-allow: unexpected message: $out"; exit 1; }
printf '# nothing\n' > "$tmp/addrs"
PATH="$tmp/bin:$PATH" "$allow" "$tmp/addrs" 2> /dev/null && { echo "kiosk-ip-allow accepted an empty list"; exit 1; }
PATH="$tmp/bin:$PATH" "$allow" "$tmp/missing" 2> /dev/null && { echo "kiosk-ip-allow accepted a missing file"; exit 1; }
[[ ! -e "$tmp/systemctl.args" ]] || { echo "kiosk-ip-allow called systemctl on bad input"; exit 1; }
# mogao-update verify (docs/updates.md) on small hand-made bundles: a good one is accepted; an
# unsigned one, one signed by another key, a changed manifest, a changed payload and one for
# another appliance are refused with their reason, before anything is written.
bash -n "$dir/bundle"
bash -n "$dir/rootfs/usr/lib/mogao/mogao-update"
"$dir/bundle" --help | grep -q "image/bundle"
if command -v openssl > /dev/null && command -v zstd > /dev/null; then
  u=$tmp/update
  mkdir -p "$u/keys" "$u/b"
  "$dir/bundle" keygen --out "$u/k1" 2> /dev/null
  "$dir/bundle" keygen --out "$u/k2" 2> /dev/null
  cp "$u/k1/update-key.pem" "$u/keys/"
  echo mogao-kiosk-amd64 > "$u/compatible"
  head -c 100000 /dev/urandom > "$u/root.img"
  head -c 1000 /dev/urandom > "$u/b/vmlinuz"
  head -c 2000 /dev/urandom > "$u/b/initrd.img"
  zstd -q "$u/root.img" -o "$u/b/root.img.zst"
  sha() { sha256sum < "$1" | cut -c1-64; }
  make_bundle() { # make_bundle OUT KEY [compatible]: signs b/manifest.toml with KEY
    { echo 'format = "mogao-update-bundle"'; echo 'version = 1'; echo 'image_version = "mogao-kiosk test"'
      echo "compatible = \"${3:-mogao-kiosk-amd64}\""; echo 'built = "2026-11-26T00:00:00Z"'; echo 'tries = 3'
      echo 'options = "ro quiet panic=10"'; echo "root_size = 100000"
      echo "root_zst_sha256 = \"$(sha "$u/b/root.img.zst")\""; echo "vmlinuz_sha256 = \"$(sha "$u/b/vmlinuz")\""
      echo "initrd_sha256 = \"$(sha "$u/b/initrd.img")\""; } > "$u/b/manifest.toml"
    openssl pkeyutl -sign -inkey "$2" -rawin -in "$u/b/manifest.toml" -out "$u/b/manifest.toml.sig"
    tar -cf "$1" -C "$u/b" manifest.toml manifest.toml.sig vmlinuz initrd.img root.img.zst
  }
  verify() { MOGAO_UPDATE_KEYS=$u/keys MOGAO_UPDATE_COMPATIBLE_FILE=$u/compatible RUNTIME_DIRECTORY=$u/run \
    "$dir/rootfs/usr/lib/mogao/mogao-update" verify "$@" 2>&1; }
  expect_refused() { # expect_refused WHAT PATTERN BUNDLE...
    local what=$1 pattern=$2 out; shift 2
    out=$(verify "$@") && { echo "mogao-update accepted $what"; exit 1; }
    grep -q "REFUSED: .*$pattern" <<< "$out" || { echo "mogao-update, $what: unexpected message: $out"; exit 1; }
  }
  make_bundle "$u/good.bundle" "$u/k1/update-signing.key"
  out=$(verify "$u/good.bundle") || { echo "mogao-update refused a good bundle: $out"; exit 1; }
  grep -q "payloads match the signed manifest" <<< "$out" || { echo "mogao-update verify: $out"; exit 1; }
  manifest_sha=$(sha "$u/b/manifest.toml")
  verify "$u/good.bundle" --manifest-sha256 "$manifest_sha" > /dev/null ||
      { echo "mogao-update refused the named bundle"; exit 1; }
  expect_refused "another bundle than the request names" "not the one the service request names" \
      "$u/good.bundle" --manifest-sha256 "${manifest_sha//?/0}"
  tar -cf "$u/unsigned.bundle" -C "$u/b" manifest.toml vmlinuz initrd.img root.img.zst
  expect_refused "an unsigned bundle" "not signed" "$u/unsigned.bundle"
  make_bundle "$u/other.bundle" "$u/k2/update-signing.key"
  expect_refused "a bundle signed by another key" "bad signature" "$u/other.bundle"
  make_bundle "$u/good.bundle" "$u/k1/update-signing.key"
  echo "# changed after signing" >> "$u/b/manifest.toml"
  tar -cf "$u/changed.bundle" -C "$u/b" manifest.toml manifest.toml.sig vmlinuz initrd.img root.img.zst
  expect_refused "a manifest changed after signing" "bad signature" "$u/changed.bundle"
  make_bundle "$u/good.bundle" "$u/k1/update-signing.key"
  head -c 1000 /dev/urandom > "$u/b/vmlinuz"
  tar -cf "$u/payload.bundle" -C "$u/b" manifest.toml manifest.toml.sig vmlinuz initrd.img root.img.zst
  expect_refused "a changed payload" "vmlinuz does not match the signed manifest" "$u/payload.bundle"
  make_bundle "$u/foreign.bundle" "$u/k1/update-signing.key" mogao-farm-amd64
  expect_refused "a bundle for another appliance" "is for 'mogao-farm-amd64'" "$u/foreign.bundle"
  rm -f "$u/keys/"*
  expect_refused "a bundle on an image without update keys" "trusts no update key" "$u/foreign.bundle"
fi
echo "image scripts: ok"
