#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# CTest entry of the render-host image tests (labels "image;qemu;farm"); see image/CMakeLists.txt.
#   farm_tests.sh check REPO                                  syntax and --help (always runs)
#   farm_tests.sh build REPO OUTDIR FARM                      image/farm/build into OUTDIR
#   farm_tests.sh qemu  REPO OUTDIR FARM KIOSK [IMAGE_TOOL]   two hosts in QEMU (farm_qemu_test.py)
# build and qemu are opt-in like the appliance's image tests (MOGAO_IMAGE_TESTS=1) and exit 77
# (skipped) with a message when not enabled or not possible here. MOGAO_FARM_IMAGE=/path/to/img
# makes "qemu" test that image instead of the one "build" made.
set -euo pipefail
mode=$1 repo=$2
skip() { echo "SKIP: $*"; exit 77; }

if [[ $mode == check ]]; then
  for f in build provision lib/farm.sh test/farm_tests.sh ../lib/debian.sh; do bash -n "$repo/image/farm/$f"; done
  sh -n "$repo/image/farm/test/selftest.sh"
  python3 - "$repo/image/farm/test/farm_qemu_test.py" "$repo/image/farm/test/farmvm.py" <<'PY'
import sys
for f in sys.argv[1:]:
    compile(open(f).read(), f, "exec")
PY
  "$repo/image/farm/build" --help | grep -q "image/farm/build"
  "$repo/image/farm/provision" --help | grep -q "image/farm/provision"
  source "$repo/image/farm/lib/farm.sh"
  grep -q "^LABEL=$MOGAO_FARM_ROOT_LABEL " "$repo/image/farm/rootfs/etc/fstab"
  grep -q "^u mogao-farm $MOGAO_FARM_UID:$MOGAO_FARM_GID " "$repo/image/farm/rootfs/usr/lib/sysusers.d/mogao-farm.conf"
  echo "farm image scripts: ok"
  exit 0
fi

outdir=$3 farm=$4
[[ "${MOGAO_IMAGE_TESTS:-0}" == 1 ]] \
  || skip "the image tests are opt-in (root, Debian mirrors, ~10 min on 2 cores; docs/services.md): set MOGAO_IMAGE_TESTS=1"
[[ $(id -u) == 0 ]] || skip "the render-host image tests need root (chroot, file ownership, network namespaces)"
image=${MOGAO_FARM_IMAGE:-$outdir/mogao-farm.img}

case $mode in
  build)
    [[ -z "${MOGAO_FARM_IMAGE:-}" ]] || skip "MOGAO_FARM_IMAGE=$MOGAO_FARM_IMAGE given: not building an image"
    source "$repo/image/lib/common.sh"
    why=$(img_build_preconditions mmdebstrap mke2fs debugfs mkfs.vfat mcopy sfdisk xz python3) || skip "$why"
    mkdir -p "$outdir"
    start=$(date +%s)
    # The appliance image's .deb cache: most packages are the same.
    "$repo/image/farm/build" --farm "$farm" --out "$outdir" --cache "$outdir/apt-cache"
    echo "$(( $(date +%s) - start ))" > "$outdir/mogao-farm.img.build-seconds"
    echo "farm_image_build: $(cat "$outdir/mogao-farm.img.build-seconds") s"
    ;;
  qemu)
    kiosk=$5 tool=${6:-}
    [[ -f "$image" ]] || skip "no image at $image (the farm_image_build test builds it)"
    args=(--image "$image" --repo "$repo" --farm "$farm" --kiosk "$kiosk" --work "$outdir/farm-qemu-test"
          --results "$outdir/farm-qemu-test-results.json")
    [[ -n "$tool" ]] && args+=(--image-tool "$tool")
    if [[ -z "${MOGAO_FARM_IMAGE:-}" && -f "$outdir/mogao-farm.img.build-seconds" ]]; then
      args+=(--build-seconds "$(cat "$outdir/mogao-farm.img.build-seconds")")
    fi
    exec python3 "$repo/image/farm/test/farm_qemu_test.py" "${args[@]}"
    ;;
  *) echo "unknown mode $mode" >&2; exit 2 ;;
esac
