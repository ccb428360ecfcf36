#!/usr/bin/env bash
# The sanitized suite one test executable at a time, for a machine where the whole
# `scripts/test --sanitize` (build everything, then ctest) does not fit in the time at hand: each
# target is built in build-asan, then only its tests run, so a run cut short has already given the
# results of the targets before. Same tree, flags and sanitizer options as scripts/test --sanitize
# (the options are read from scripts/test, which owns them); reports accumulate in
# build-asan/sanitizer-reports/ and any report there fails the run.
#
#   fuzz/sanitize_by_target.sh core_test io_test estimation_test ...   # in this order
#   fuzz/sanitize_by_target.sh all                                      # then the rest of the suite
#
# VIEWLINE_JOBS (default 2) build jobs and ctest --parallel. The tests already run are listed in
# build-asan/sanitize-by-target.done (delete it to start over); per-target logs go beside it.
set -uo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${VIEWLINE_BUILD_DIR:-$root/build}-asan"
reports="$build/sanitizer-reports"
# shellcheck disable=SC2034  # used by the option lines read from scripts/test below
supp="$root/fuzz/sanitizer-suppressions"
jobs="${VIEWLINE_JOBS:-2}"
mkdir -p "$reports"
eval "$(grep -E '^export (ASAN|LSAN|UBSAN)_OPTIONS=' "$root/scripts/test")"
eval "$(grep -E '^opt=' "$root/scripts/test")"   # opt=(...): the optimisation level of the tree
export CCACHE_BASEDIR="$root"
# shellcheck disable=SC2154  # opt comes from the eval above
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER_LAUNCHER=ccache \
  -DCMAKE_CXX_COMPILER=g++ -DVIEWLINE_SANITIZE=address,undefined "${opt[@]}" >/dev/null || exit 1
done_list="$build/sanitize-by-target.done"
touch "$done_list"
status=0
for t in "$@"; do
  s=$SECONDS
  if ! cmake --build "$build" --parallel "$jobs" --target "$t" >"$build/sanitize-by-target.$t.build.log" 2>&1; then
    echo "$(date -u +%T) $t: BUILD FAILED ($build/sanitize-by-target.$t.build.log)"; status=1; continue
  fi
  echo "$(date -u +%T) $t: built in $((SECONDS - s)) s"
  # The tests not run yet whose command is this executable (all: every test), as ctest numbers
  # (the order of --show-only=json-v1 is ctest's numbering).
  numbers=$(cd "$build" && ctest --show-only=json-v1 | python3 -c '
import json, os, sys
target, done = sys.argv[1], set(open(sys.argv[2]).read().split())
for i, x in enumerate(json.load(sys.stdin)["tests"], 1):
    cmd = x.get("command") or [""]
    if x["name"] not in done and (target == "all" or os.path.basename(cmd[0]) == target):
        print(i, x["name"])' "$t" "$done_list")
  if [ -z "$numbers" ]; then echo "$(date -u +%T) $t: no tests left to run"; continue; fi
  s=$SECONDS
  log="$build/sanitize-by-target.$t.ctest.log"
  (cd "$build" && ctest --output-on-failure --parallel "$jobs" --timeout 1800 \
     -I "0,0,0,$(cut -d' ' -f1 <<<"$numbers" | paste -sd,)") >"$log" 2>&1 || status=1
  echo "$(date -u +%T) $t: $(grep -E 'tests passed|tests failed' "$log") ($((SECONDS - s)) s wall)"
  grep -E '^ +[0-9]+ - ' "$log" || true
  cut -d' ' -f2 <<<"$numbers" >>"$done_list"
done
if compgen -G "$reports/*" >/dev/null; then
  echo "sanitizer reports in $reports:" >&2
  ls "$reports" >&2
  status=1
fi
exit "$status"
