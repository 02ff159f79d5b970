#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# .ci/check-line-length must refuse a line over 120 columns, naming file, line and columns, in each
# file type it owns, and let through only its stated exceptions (a Markdown table row, a line inside
# a generated block, a line that is a single URL) and the file types it does not own (C++).
# (The tree as it is passes: line_length_check.)
# Usage: line_length_check_test.sh SOURCE_DIR WORK_DIR
set -uo pipefail
src=$1 work=$2
rm -rf "$work" && mkdir -p "$work"
long=$(printf 'word %.0s' $(seq 1 30))  # 150 columns
failures=0
check() {  # check "what" expected-exit file [needle]
  local what=$1 want=$2 file=$3 needle=${4:-}
  local out rc
  out=$(python3 "$src/.ci/check-line-length" "$file" 2>&1); rc=$?
  if [[ $rc -ne $want || ( -n $needle && $out != *"$needle"* ) ]]; then
    echo "FAIL: $what: exit $rc, expected $want${needle:+ and '$needle'} in:"; echo "$out"
    failures=$((failures + 1))
  else
    echo "ok: $what"
  fi
}
printf '# Title\n\n%s\n' "$long" > "$work/prose.md"
check "a long prose line in Markdown is refused" 1 "$work/prose.md" "prose.md:3: 150 columns (limit 120)"
printf '| a | b |\n|---|---|\n| %s | x |\n' "$long" > "$work/table.md"
check "a Markdown table row may be long" 0 "$work/table.md"
printf 'text\n<!-- generated:x -->\n%s\n<!-- /generated -->\n' "$long" > "$work/generated.md"
check "a line inside a generated block may be long" 0 "$work/generated.md"
printf 'text\n<!-- generated:x -->\nshort\n<!-- /generated -->\n%s\n' "$long" > "$work/after.md"
check "a long line after a generated block is refused" 1 "$work/after.md" "after.md:5: 150 columns"
printf 'See:\n\nhttps://example.org/%s\n' "$(printf 'a%.0s' $(seq 1 130))" > "$work/url.md"
check "a line that is a single URL may be long" 0 "$work/url.md"
printf 'echo %s\n' "$long" > "$work/script.sh"
check "a long shell line is refused" 1 "$work/script.sh" "script.sh:1: 155 columns"
printf '#!/usr/bin/env python3\nprint("%s")\n' "$long" > "$work/tool"
check "a long line of a Python script without extension is refused" 1 "$work/tool" "tool:2:"
printf 'add_test(NAME x COMMAND %s)\n' "$long" > "$work/CMakeLists.txt"
check "a long CMake line is refused" 1 "$work/CMakeLists.txt" "CMakeLists.txt:1:"
printf 'a:\n  b: "%s"\n' "$long" > "$work/rules.yml"
check "a long YAML line is refused" 1 "$work/rules.yml" "rules.yml:2:"
printf '[Service]\nExecStart=/bin/echo %s\n' "$long" > "$work/x.service"
check "a long unit line is refused" 1 "$work/x.service" "x.service:2:"
printf 'int x; // %s\n' "$long" > "$work/code.cpp"
check "C++ is left to .ci/check-format" 0 "$work/code.cpp"
echo "$failures failed"
[[ $failures -eq 0 ]]
