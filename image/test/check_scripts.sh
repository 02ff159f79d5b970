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
echo "image scripts: ok"
