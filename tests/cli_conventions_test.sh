#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Every program follows the command-line conventions of common/program_cli.h (docs/cli.md):
#   --version prints "NAME VERSION" and exits 0; --help exits 0 and shows defaults ("=VALUE");
#   an unknown flag exits 2 with a message naming it on stderr -- mogao-farm under mpirun too, on
#   every rank (the job's status is the ranks' worst).
#   cli_conventions_test.sh MPIEXEC VERSION NAME=PATH [NAME=PATH ...]
set -u
mpiexec=$1 version=$2
shift 2
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
out=$(mktemp) err=$(mktemp)
trap 'rm -f "$out" "$err"' EXIT
check() {  # check NAME EXPECTED_STATUS ARGS... (runs "${run[@]}" ARGS)
  local name=$1 want=$2
  shift 2
  "${run[@]}" "$@" > "$out" 2> "$err" < /dev/null
  local rc=$?
  [ $rc -eq "$want" ] || fail "$name $*: exit $rc, expected $want (stderr: $(head -c 300 "$err"))"
  return $rc
}
for entry in "$@"; do
  name=${entry%%=*} exe=${entry#*=}
  run=("$exe")
  check "$name" 0 --version && { grep -qx "$name $version" "$out" ||
      fail "$name --version printed '$(head -c 200 "$out")', not '$name $version'"; }
  check "$name" 0 --help && { grep -q "$name" "$out" || fail "$name --help does not name the program"; }
  # A program whose top level has only subcommands: its first subcommand's help shows the defaults
  # and takes the unknown flag (a missing subcommand would be reported first).
  sub=$(grep -A200 -E '^Subcommands:' "$out" | sed -n 2p | awk '{print $1}')
  if [ -n "$sub" ]; then check "$name" 0 "$sub" --help; fi
  # Defaults: "--threads UINT=1", "--scale FLOAT:FLOAT in [0.05 - 1]=0.5"; a help without any
  # option that takes a value (mogao-camera list) has none to show.
  if grep -qE '^ +-[^ ]+ +[A-Z]{3,}' "$out" && ! grep -qE '^ +-[^ ]+ +[A-Z].*[^ =]=[^ =]' "$out"; then
    fail "$name ${sub:+$sub }--help shows no default (TYPE=VALUE)"
  fi
  check "$name" 2 ${sub:+"$sub"} --no-such-flag-xyz
  # The message names the unknown flag, or the required one CLI11 checks first.
  grep -qE -- "--no-such-flag-xyz|is required" "$err" || fail \
      "$name: the usage error names no flag (stderr: $(head -c 300 "$err"))"
  if [ "$name" = mogao-farm ]; then
    # Under MPI: rank 0 reports, the others exit 2 quietly; mpirun passes the status on.
    run=("$mpiexec" -n 2 "$exe")
    check "$name (2 MPI ranks)" 2 serve --no-such-flag-xyz
  fi
done
[ $fails -eq 0 ] && echo "PASS: $# programs follow the command-line conventions" && exit 0
echo "$fails check(s) failed"
exit 1
