#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# CTest entry of the opt-in image tests (labels "image;qemu"); see image/CMakeLists.txt.
#   image_tests.sh build REPO OUTDIR KIOSK
#   image_tests.sh boot  REPO OUTDIR KIOSK FARM IMAGE_TOOL MPIEXEC [CAMERA_TEST [LIBCAMERA_TEST]]
#   image_tests.sh service-card REPO OUTDIR KIOSK   the configuration partition wiped: the service card
#   image_tests.sh powercut REPO OUTDIR KIOSK FARM CALIBRATE RIG_FILM   power cuts during writes
#     (MOGAO_POWERCUT_CUTS cuts per write, default 3; MOGAO_POWERCUT_REBOOT_EVERY, default 0: no
#     reboot on a cut disk, the full run does those; MOGAO_POWERCUT_SEED, default 1)
#   image_tests.sh service-mode REPO OUTDIR KIOSK FARM CALIBRATE RIG_FILM   signed USB-stick requests
#   image_tests.sh update REPO OUTDIR KIOSK FARM   A/B updates through the service mode, a rollback
# The image the build mode makes trusts a test update key made next to it (OUTDIR/update-test-key/,
# image/bundle keygen): the update test signs its bundles with it. With MOGAO_IMAGE, the update
# test needs MOGAO_UPDATE_SIGNING_KEY (the private key whose public key that image trusts).
# Exit 77 (skipped) with a message when not enabled (MOGAO_IMAGE_TESTS=1) or not possible here.
set -u
mode=$1 repo=$2 outdir=$3 kiosk=$4
skip() { echo "SKIP: $*"; exit 77; }

[[ "${MOGAO_IMAGE_TESTS:-0}" == 1 ]] \
  || skip "the image tests are opt-in (5-10 min on 2 cores, root, Debian mirrors; docs/image.md):"\
" set MOGAO_IMAGE_TESTS=1"
[[ $(id -u) == 0 ]] || skip "the image tests need root (chroot, file ownership)"

case $mode in
  build)
    if [[ -n "${MOGAO_IMAGE:-}" ]]; then skip "MOGAO_IMAGE=$MOGAO_IMAGE given: not building an image"; fi
    source "$repo/image/lib/common.sh"
    why=$(img_build_preconditions mmdebstrap mke2fs mkfs.vfat mcopy sfdisk xz python3) || skip "$why"
    mkdir -p "$outdir"
    start=$(date +%s)
    [[ -f "$outdir/update-test-key/update-key.pem" ]] || "$repo/image/bundle" keygen --out \
        "$outdir/update-test-key" || exit 1
    "$repo/image/build" --kiosk "$kiosk" --out "$outdir" --cache "$outdir/apt-cache" \
      --update-key "$outdir/update-test-key/update-key.pem" || exit 1
    echo "image_build: $(( $(date +%s) - start )) s"
    ;;
  boot)
    farm=$5 tool=$6 mpiexec=$7 camera=${8:-} libcamera=${9:-} calibrate_sim=${10:-}
    image=${MOGAO_IMAGE:-$outdir/mogao-kiosk.img}
    [[ -f "$image" ]] || skip "no image at $image (the image_build test builds it)"
    args=(--image "$image" --repo "$repo" --kiosk "$kiosk" --farm "$farm" --image-tool "$tool"
          --work "$outdir/qemu-test" --results "$outdir/qemu-test-results.json")
    [[ -n "$mpiexec" ]] && args+=(--mpiexec "$mpiexec")
    [[ -n "$camera" ]] && args+=(--camera-test "$camera")
    [[ -n "$libcamera" ]] && args+=(--libcamera-test "$libcamera")
    [[ -n "$calibrate_sim" ]] && args+=(--calibrate-sim "$calibrate_sim")
    exec python3 "$repo/image/test/qemu_boot_test.py" "${args[@]}"
    ;;
  service-card)
    image=${MOGAO_IMAGE:-$outdir/mogao-kiosk.img}
    [[ -f "$image" ]] || skip "no image at $image (the image_build test builds it)"
    exec python3 "$repo/image/test/qemu_service_card_test.py" --image "$image" --repo "$repo" \
      --work "$outdir/qemu-service-card"
    ;;
  powercut)
    farm=$5 calibrate=$6 rig_film=$7
    image=${MOGAO_IMAGE:-$outdir/mogao-kiosk.img}
    [[ -f "$image" ]] || skip "no image at $image (the image_build test builds it)"
    exec python3 "$repo/image/test/qemu_powercut_test.py" --image "$image" --repo "$repo" --kiosk "$kiosk" \
      --farm "$farm" --calibrate "$calibrate" --rig-film "$rig_film" --binaries-into-image \
      --cuts "${MOGAO_POWERCUT_CUTS:-3}" --reboot-every "${MOGAO_POWERCUT_REBOOT_EVERY:-0}" \
      --work "$outdir/qemu-powercut" --results "$outdir/qemu-powercut-results.json"
    ;;
  service-mode)
    farm=$5 calibrate=$6 rig_film=$7
    image=${MOGAO_IMAGE:-$outdir/mogao-kiosk.img}
    [[ -f "$image" ]] || skip "no image at $image (the image_build test builds it)"
    exec python3 "$repo/image/test/qemu_service_mode_test.py" --image "$image" --repo "$repo" --kiosk "$kiosk" \
      --farm "$farm" --calibrate "$calibrate" --rig-film "$rig_film" --work "$outdir/qemu-service-mode"
    ;;
  update)
    farm=$5
    image=${MOGAO_IMAGE:-$outdir/mogao-kiosk.img}
    [[ -f "$image" ]] || skip "no image at $image (the image_build test builds it)"
    key=${MOGAO_UPDATE_SIGNING_KEY:-$outdir/update-test-key/update-signing.key}
    [[ -f "$key" ]] || skip \
        "no update signing key $key (image_build makes one; with MOGAO_IMAGE set MOGAO_UPDATE_SIGNING_KEY)"
    exec python3 "$repo/image/test/qemu_update_test.py" --image "$image" --repo "$repo" --kiosk "$kiosk" \
      --farm "$farm" --update-key "$key" --work "$outdir/qemu-update" --results "$outdir/qemu-update-results.json"
    ;;
  *) echo "unknown mode $mode" >&2; exit 2 ;;
esac
