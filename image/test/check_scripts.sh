#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# image_scripts test: the image scripts parse, and their --help works (no root, no network).
set -eu
dir=$1
bash -n "$dir/build"
bash -n "$dir/provision"
bash -n "$dir/lib/common.sh"
bash -n "$dir/test/image_tests.sh"
sh -n "$dir/test/selftest.sh"
python3 - "$dir/test/qemu_boot_test.py" "$dir/test/qemu_common.py" "$dir/lib/prune_modules.py" <<'PY'
import sys
for f in sys.argv[1:]:
    compile(open(f).read(), f, "exec")
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
echo "image scripts: ok"
