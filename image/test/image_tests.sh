#!/bin/bash
# CTest entry of the opt-in image tests (labels "image;qemu"); see image/CMakeLists.txt.
#   image_tests.sh build REPO OUTDIR KIOSK
#   image_tests.sh boot  REPO OUTDIR KIOSK FARM IMAGE_TOOL MPIEXEC [CAMERA_TEST]
# Exit 77 (skipped) with a message when not enabled (MOGAO_IMAGE_TESTS=1) or not possible here.
set -u
mode=$1 repo=$2 outdir=$3 kiosk=$4
skip() { echo "SKIP: $*"; exit 77; }

[[ "${MOGAO_IMAGE_TESTS:-0}" == 1 ]] \
  || skip "the image tests are opt-in (5-10 min on 2 cores, root, Debian mirrors; docs/image.md): set MOGAO_IMAGE_TESTS=1"
[[ $(id -u) == 0 ]] || skip "the image tests need root (chroot, file ownership)"

case $mode in
  build)
    if [[ -n "${MOGAO_IMAGE:-}" ]]; then skip "MOGAO_IMAGE=$MOGAO_IMAGE given: not building an image"; fi
    for tool in mmdebstrap mke2fs mkfs.vfat mcopy sfdisk xz python3; do
      command -v "$tool" >/dev/null || skip "$tool not found (apt-get install mmdebstrap e2fsprogs dosfstools mtools fdisk xz-utils)"
    done
    [[ -f /usr/lib/systemd/boot/efi/systemd-bootx64.efi ]] || skip "systemd-boot not found (apt-get install systemd-boot-efi)"
    mirror=${MOGAO_IMAGE_MIRROR:-http://deb.debian.org/debian}
    python3 - "$mirror/dists/bookworm/Release" <<'PY' || skip "the Debian mirror $mirror is not reachable"
import sys, urllib.request
urllib.request.urlopen(urllib.request.Request(sys.argv[1], method="HEAD"), timeout=20)
PY
    mkdir -p "$outdir"
    start=$(date +%s)
    "$repo/image/build" --kiosk "$kiosk" --out "$outdir" --cache "$outdir/apt-cache" || exit 1
    echo "image_build: $(( $(date +%s) - start )) s"
    ;;
  boot)
    farm=$5 tool=$6 mpiexec=$7 camera=${8:-}
    image=${MOGAO_IMAGE:-$outdir/mogao-kiosk.img}
    [[ -f "$image" ]] || skip "no image at $image (the image_build test builds it)"
    args=(--image "$image" --repo "$repo" --kiosk "$kiosk" --farm "$farm" --image-tool "$tool"
          --work "$outdir/qemu-test" --results "$outdir/qemu-test-results.json")
    [[ -n "$mpiexec" ]] && args+=(--mpiexec "$mpiexec")
    [[ -n "$camera" ]] && args+=(--camera-test "$camera")
    exec python3 "$repo/image/test/qemu_boot_test.py" "${args[@]}"
    ;;
  *) echo "unknown mode $mode" >&2; exit 2 ;;
esac
