#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# bench/regenerate-docs --check must fail, naming the fault, on a copy of docs/benchmarks.md with:
# an unclosed marker, an unknown table, a table's markers removed, a measured figure pasted into the
# prose; and on a benchmark that cannot run. (The doc as it is passes: bench_regenerate_docs_check.)
# Usage: regenerate_docs_test.sh SOURCE_DIR BUILD_DIR
set -uo pipefail
src=$1 build=$2
gen="python3 $src/bench/regenerate-docs --build $build --main-job-out $src/bench/testdata"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
expect_fail() {  # expect_fail "what" "expected text" doc [args...]
  local what=$1 needle=$2 doc=$3; shift 3
  local out rc
  out=$($gen --check --doc "$doc" "$@" 2>&1); rc=$?
  if [[ $rc -ne 1 || $out != *"$needle"* ]]; then
    echo "FAIL: $what: exit $rc, expected 1 and '$needle' in:"; echo "$out"; failures=$((failures + 1))
  else
    echo "ok: $what is refused"
  fi
}
doc=$src/docs/benchmarks.md
sed '0,/^<!-- \/generated -->$/{/^<!-- \/generated -->$/d}' "$doc" > "$work/unclosed.md"
expect_fail "an unclosed marker" "has no <!-- /generated -->" "$work/unclosed.md"
sed 's/^<!-- generated:jpeg-quality -->$/<!-- generated:jpeg-qualty -->/' "$doc" > "$work/unknown.md"
expect_fail "an unknown table" "unknown table generated:jpeg-qualty" "$work/unknown.md"
sed '/^<!-- generated:jpeg-quality -->$/,/^<!-- \/generated -->$/d' "$doc" > "$work/missing.md"
expect_fail "a table without markers" "tables without markers in the doc: jpeg-quality" "$work/missing.md" --only jpeg
sed 's/^## JPEG quality$/## JPEG quality\n\nThe main job renders at 2.22 s\/frame and 8.1 Mrays\/s./' "$doc" \
    > "$work/figure.md"
expect_fail "a figure in the prose" "measured figure in prose" "$work/figure.md" --only jpeg
out=$(python3 "$src/bench/regenerate-docs" --check --build "$work/no-build" --only jpeg 2>&1); rc=$?
if [[ $rc -ne 1 || $out != *"cannot run"* ]]; then
  echo "FAIL: a benchmark that cannot run: exit $rc:"; echo "$out"; failures=$((failures + 1))
else
  echo "ok: a benchmark that cannot run is refused"
fi
echo "$failures failed"
[[ $failures -eq 0 ]]
