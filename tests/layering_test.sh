#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The layering check must fail on each wrong-way edge the structure issue found in the old tree
# (and on a wrong-way CMake link line), each named in its output; and pass on the tree as it is.
# Usage: layering_test.sh SOURCE_DIR
set -uo pipefail
src=$1
check="python3 $src/.ci/check-layering --root $src"
failures=0
expect_fail() {  # expect_fail "what" "expected text" args...
  local what=$1 needle=$2; shift 2
  local out rc
  out=$($check "$@" 2>&1); rc=$?
  if [[ $rc -ne 1 || $out != *"$needle"* ]]; then
    echo "FAIL: $what: exit $rc, expected 1 and '$needle' in:"; echo "$out"; failures=$((failures + 1))
  else
    echo "ok: $what is refused"
  fi
}
$check > /dev/null || { echo "FAIL: the tree itself does not pass"; $check; failures=$((failures + 1)); }
expect_fail "drivers/egl -> appliance/warp" "drivers/egl -> appliance/warp" \
  --inject drivers/egl/warp_blend_renderer.h=appliance/warp/composite.h
expect_fail "drivers/headless -> renderfarm/encode" "drivers/headless -> renderfarm/encode" \
  --inject drivers/headless/headless_output.cpp=renderfarm/encode/contact_sheet.h
expect_fail "renderfarm/link -> drivers" "renderfarm/link -> drivers" \
  --inject renderfarm/link/tls_material.cpp=drivers/output.h
expect_fail "kiosk -> renderfarm/farm" "kiosk -> renderfarm/farm" \
  --inject kiosk/main.cpp=renderfarm/farm/serve.h
expect_fail "appliance/tracker -> appliance/navigation" "appliance/tracker -> appliance/navigation" \
  --inject appliance/tracker/tag_tracker.h=appliance/navigation/navigator.h
expect_fail "common -> drivers" "common -> drivers" --inject common/image.h=drivers/output.h
expect_fail "link line mogao_tracker -> mogao_navigation" "mogao_tracker links mogao_navigation" \
  --inject-link mogao_tracker=mogao_navigation
expect_fail "link line mogao_egl -> mogao_warp" "mogao_egl links mogao_warp" --inject-link mogao_egl=mogao_warp
echo "$failures failed"
[[ $failures -eq 0 ]]
