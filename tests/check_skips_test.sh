#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# .ci/check-skips passes a report whose only skips are allowlisted hardware, and fails one where
# a test that CI must run skipped (e.g. an e2e test without network namespaces).
# Usage: check_skips_test.sh SOURCE_DIR WORK_DIR
set -uo pipefail
src=$1 work=$2
mkdir -p "$work"
report() {  # report FILE SKIPPED_NAME...
  local file=$1; shift
  { echo '<?xml version="1.0" encoding="UTF-8"?>'
    echo '<testsuite name="t" tests="3" failures="0" skipped="1">'
    echo '<testcase name="Unit.Runs" classname="Unit.Runs" time="0.1" status="run"/>'
    for name in "$@"; do
      echo "<testcase name=\"$name\" classname=\"$name\" time=\"0.1\" status=\"notrun\">"\
"<skipped message=\"SKIP_RETURN_CODE=77\"/></testcase>"
    done
    echo '</testsuite>'; } > "$file"
}
failures=0
report "$work/ok.xml" V4l2CaptureVivid.StreamsGrey mogao_kms_probe_lists
out=$(python3 "$src/.ci/check-skips" "$work/ok.xml") || { echo "FAIL: allowlisted skips refused: $out";
    failures=$((failures + 1)); }
[[ $out == *"1 passed, 0 failed, 2 skipped"* ]] || { echo "FAIL: closing line: $out"; failures=$((failures + 1)); }
report "$work/bad.xml" V4l2CaptureVivid.StreamsGrey kiosk_e2e_netns
if out=$(python3 "$src/.ci/check-skips" "$work/bad.xml"); then
  echo "FAIL: an unexpected skip of kiosk_e2e_netns passed: $out"; failures=$((failures + 1))
fi
[[ $out == *"kiosk_e2e_netns  <- NOT on .ci/skip-allowlist"* && $out == *"1 passed, 1 failed, 1 skipped"* ]] \
  || { echo "FAIL: the report does not name the unexpected skip: $out"; failures=$((failures + 1)); }
echo "$failures failed"
[[ $failures -eq 0 ]]
