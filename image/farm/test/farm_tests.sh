#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# CTest entry of the render-host image tests (labels "image;qemu;farm"); see image/CMakeLists.txt.
#   farm_tests.sh check    REPO                       syntax and --help (always runs)
#   farm_tests.sh packages REPO PKGDIR                .ci/package: the Debian packages into PKGDIR
#   farm_tests.sh build    REPO OUTDIR PKGDIR         image/farm/build into OUTDIR (the base for
#                                                     PKGDIR's mogao-farm package)
#   farm_tests.sh qemu     REPO OUTDIR PKGDIR FARM KIOSK [IMAGE_TOOL]
#                                                     two hosts in QEMU that install PKGDIR's
#                                                     mogao-farm package (farm_qemu_test.py)
# packages, build and qemu are opt-in like the appliance's image tests (MOGAO_IMAGE_TESTS=1) and
# exit 77 (skipped) with a message when not enabled or not possible here.
# MOGAO_FARM_IMAGE=/path/to/img makes "qemu" test that image instead of the one "build" made.
set -euo pipefail
mode=$1 repo=$2
skip() { echo "SKIP: $*"; exit 77; }

if [[ $mode == check ]]; then
  for f in build provision lib/farm.sh test/farm_tests.sh ../lib/debian.sh; do bash -n "$repo/image/farm/$f"; done
  sh -n "$repo/image/farm/test/selftest.sh"
  # docs/services.md's table of the QEMU test is written by this script from a run's results.
  python3 "$repo/image/farm/test/results_table.py" --check --doc "$repo/docs/services.md"
  # The packet filter's ruleset: the farm network let in, a bad network file closes it (and says so).
  fw="$repo/image/farm/rootfs/usr/lib/mogao/farm-firewall" tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' EXIT
  sh -n "$fw"
  printf '10.77.0.0/24 # farm\nfd00:6d6f::/64\n' > "$tmp/net"; echo 'MOGAO_LISTEN=[::]:7443' > "$tmp/env"
  sh "$fw" --print "$tmp/net" "$tmp/env" > "$tmp/good"
  grep -q 'ip saddr { 10.77.0.0/24 } accept' "$tmp/good" && grep -q 'ip6 saddr { fd00:6d6f::/64 } accept' "$tmp/good" \
    && grep -q 'tcp dport 7443 accept' "$tmp/good" && grep -q 'policy drop' "$tmp/good" \
    || { echo "farm-firewall: unexpected ruleset:"; cat "$tmp/good"; exit 1; }
  printf '10.77.0.0/24\nnot-a-prefix\n' > "$tmp/bad"
  if sh "$fw" --print "$tmp/bad" > "$tmp/closed" 2> "$tmp/err"; then
    echo "farm-firewall: a bad network file was accepted"; exit 1
  fi
  grep -q "$tmp/bad:2: 'not-a-prefix'" "$tmp/err" && ! grep -q saddr "$tmp/closed" \
    || { echo "farm-firewall: a bad file must close Open MPI's ports and name the line:"
         cat "$tmp/err" "$tmp/closed"; exit 1; }
  # What the parser must refuse (each would have made nft fail at boot, or opened the host to all).
  for bad in 1.2.3.4/33 fd00::/129 300.1.1.1/8 1.2.3.4:80 . "10.0.0.1 10.0.0.2" dead.beef ::/0 0.0.0.0/0 10.0.0.0; do
    printf '%s\n' "$bad" > "$tmp/bad"
    if sh "$fw" --print "$tmp/bad" > "$tmp/closed2" 2> /dev/null || grep -q saddr "$tmp/closed2"; then
      echo "farm-firewall: '$bad' was taken for a prefix"; exit 1
    fi
  done
  # nftables itself (root and nft: in CI), in a network namespace of its own: both rulesets parse
  # without /etc/protocols (the image has none: 'ipv6-icmp' failed there at every boot), the
  # good one loads with the farm network, and one nft refuses (port 99999) loads closed, exit 1.
  if command -v nft > /dev/null && [[ $(id -u) == 0 ]] && unshare -n -m true 2> /dev/null; then
    for rs in good closed; do
      unshare -n -m sh -c 'mount --bind /dev/null /etc/protocols && nft -c -f "$1"' _ "$tmp/$rs" \
        || { echo "farm-firewall: nft refuses the $rs ruleset without /etc/protocols"; exit 1; }
    done
    unshare -n sh -c 'sh "$1" "$2" "$3" && nft list table inet mogao_farm' _ "$fw" "$tmp/net" "$tmp/env" \
        > "$tmp/loaded" 2>&1 \
      && grep -qE 'ip saddr (\{ )?10.77.0.0/24( \})? accept' "$tmp/loaded" \
      || { echo "farm-firewall: the good filter did not load:"; cat "$tmp/loaded"; exit 1; }
    echo 'MOGAO_LISTEN=[::]:99999' > "$tmp/env-bad"
    if unshare -n sh -c 'sh "$1" "$2" "$3"; rc=$?; nft list table inet mogao_farm; exit $rc' \
        _ "$fw" "$tmp/net" "$tmp/env-bad" \
        > "$tmp/loaded" 2>&1 || ! grep -q 'policy drop' "$tmp/loaded" || grep -q saddr "$tmp/loaded"; then
      echo "farm-firewall: a ruleset nft refuses must load the closed filter and exit 1:"; cat "$tmp/loaded"; exit 1
    fi
  else
    echo "farm-firewall: nft not run (needs root, nftables and namespaces)"
  fi
  python3 - "$repo/image/farm/test/farm_qemu_test.py" "$repo/image/farm/test/farmvm.py" <<'PY'
import sys
for f in sys.argv[1:]:
    compile(open(f).read(), f, "exec")
PY
  "$repo/image/farm/build" --help | grep -q "image/farm/build"
  "$repo/image/farm/provision" --help | grep -q "image/farm/provision"
  source "$repo/image/lib/common.sh"
  source "$repo/image/farm/lib/farm.sh"
  # Provisioning takes a host's own files and refuses the farm's configuration, which the package's
  # conffiles own (written on the host after apt install), naming the file.
  mkdir -p "$tmp/host/etc/mogao"
  printf '10.77.0.0/24\n' > "$tmp/host/etc/mogao/farm-network"
  (farm_check_host_dir "$tmp/host") || { echo "provisioning refused a host's own files"; exit 1; }
  for f in farm.env farm-hosts pki; do
    if [[ $f == pki ]]; then mkdir "$tmp/host/etc/mogao/pki"; else : > "$tmp/host/etc/mogao/$f"; fi
    if (farm_check_host_dir "$tmp/host") 2> "$tmp/provision.err"; then echo "provisioning took etc/mogao/$f"; exit 1; fi
    grep -q "etc/mogao/$f: the farm's configuration is written after" "$tmp/provision.err" \
      || { echo "provisioning refused etc/mogao/$f without saying why:"; cat "$tmp/provision.err"; exit 1; }
    rm -rf "$tmp/host/etc/mogao/$f"
  done
  grep -q "^LABEL=$MOGAO_FARM_ROOT_LABEL " "$repo/image/farm/rootfs/etc/fstab"
  grep -q "^u mogao-farm $MOGAO_FARM_UID:$MOGAO_FARM_GID " "$repo/systemd/mogao-farm.sysusers"
  echo "farm image scripts: ok"
  exit 0
fi

[[ "${MOGAO_IMAGE_TESTS:-0}" == 1 ]] \
  || skip "the image tests are opt-in (root, Debian mirrors, ~10 min on 2 cores; docs/services.md):" \
    "set MOGAO_IMAGE_TESTS=1"
[[ $(id -u) == 0 ]] || skip "the render-host image tests need root (chroot, file ownership, network namespaces)"

case $mode in
  packages)
    pkgdir=$3
    mkdir -p "$pkgdir"
    rm -f "$pkgdir"/*.deb
    start=$(date +%s)
    bash "$repo/.ci/package" "$pkgdir" > "$pkgdir/package.log" 2>&1 \
      || { tail -n 40 "$pkgdir/package.log"
           echo "bash .ci/package $pkgdir failed (log: $pkgdir/package.log)"; exit 1; }
    grep -E '^(ccache|lintian|package build)' "$pkgdir/package.log" || true
    echo "farm_packages_build: $(( $(date +%s) - start )) s"
    ;;
  build)
    outdir=$3
    [[ -z "${MOGAO_FARM_IMAGE:-}" ]] || skip "MOGAO_FARM_IMAGE=$MOGAO_FARM_IMAGE given: not building an image"
    deb=${MOGAO_FARM_DEB:-$(ls "$4"/mogao-farm_*.deb 2>/dev/null | head -n1)}
    [[ -f "$deb" ]] || {
      echo "no mogao-farm package in $4 (farm_packages_build makes it; or MOGAO_FARM_DEB=FILE)"; exit 1
    }
    source "$repo/image/lib/common.sh"
    why=$(img_build_preconditions mmdebstrap mke2fs debugfs mkfs.vfat mcopy sfdisk xz python3) || skip "$why"
    mkdir -p "$outdir"
    start=$(date +%s)
    # The appliance image's .deb cache: most packages are the same.
    "$repo/image/farm/build" --deb "$deb" --out "$outdir" --cache "$outdir/apt-cache"
    echo "$(( $(date +%s) - start ))" > "$outdir/mogao-farm.img.build-seconds"
    echo "farm_image_build: $(cat "$outdir/mogao-farm.img.build-seconds") s"
    ;;
  qemu)
    outdir=$3 farm=$5 kiosk=$6 tool=${7:-}
    deb=${MOGAO_FARM_DEB:-$(ls "$4"/mogao-farm_*.deb 2>/dev/null | head -n1)}
    [[ -n "$deb" ]] || skip "no mogao-farm package in $4 (farm_packages_build makes it; or MOGAO_FARM_DEB=FILE)"
    image=${MOGAO_FARM_IMAGE:-$outdir/mogao-farm.img}
    [[ -f "$image" ]] || skip "no image at $image (the farm_image_build test builds it)"
    args=(--image "$image" --deb "$deb" --repo "$repo" --farm "$farm" --kiosk "$kiosk" --work "$outdir/farm-qemu-test"
          --results "$outdir/farm-qemu-test-results.json")
    [[ -n "$tool" ]] && args+=(--image-tool "$tool")
    if [[ -z "${MOGAO_FARM_IMAGE:-}" && -f "$outdir/mogao-farm.img.build-seconds" ]]; then
      args+=(--build-seconds "$(cat "$outdir/mogao-farm.img.build-seconds")")
    fi
    exec python3 "$repo/image/farm/test/farm_qemu_test.py" "${args[@]}"
    ;;
  *) echo "unknown mode $mode" >&2; exit 2 ;;
esac
