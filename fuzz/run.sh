#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (build-fuzz, or $VIEWLINE_FUZZ_BUILD_DIR) and fuzzes them
# one at a time, niced, from the committed seeds (fuzz/corpus/<target>, copied: the committed corpus
# is not touched). Logs and the grown corpora stay in the build directory.
#
#   fuzz/run.sh [RUNS] [TARGET...]     RUNS default 1000000; targets default: all
#   VIEWLINE_FUZZ_SECONDS=N            also stop each target after N seconds (libFuzzer -max_total_time)
#
# A target's summary (executions, time, cov/ft, corpus size) is its log's last "#N DONE" line;
# fuzz/README.md has the figures of the last full run. Crash, leak, timeout and OOM inputs are
# written to <build>/fuzz-findings/<target>/ and make the script fail.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${VIEWLINE_FUZZ_BUILD_DIR:-$root/build-fuzz}"
runs="${1:-1000000}"
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(scenario_yaml config_set sweep_spec camera_xml opencv_yaml rig csv_log)

launcher=()
command -v ccache >/dev/null 2>&1 && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++-14 \
  -DVIEWLINE_BUILD_FUZZ=ON -DVIEWLINE_SANITIZE=address,undefined "${launcher[@]}" >/dev/null
nice -n 10 cmake --build "$build" --target viewline_fuzz_all --parallel "${VIEWLINE_JOBS:-2}"

max_len_of() {
  case "$1" in
    config_set|csv_log) echo 2048 ;;
    *) echo 4096 ;;
  esac
}

export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:abort_on_error=0"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
status=0
for t in "${targets[@]}"; do
  work="$build/fuzz-corpus/$t"
  findings="$build/fuzz-findings/$t"
  log="$build/fuzz-logs/$t.log"
  mkdir -p "$work" "$findings" "$(dirname "$log")"
  cp -n "$root/fuzz/corpus/$t"/* "$work"/ 2>/dev/null || true
  echo "fuzz/run.sh: $t ($runs runs) -> $log"
  start=$(date +%s)
  if ! nice -n 10 "$build/fuzz/fuzz_$t" -runs="$runs" -max_len="$(max_len_of "$t")" -timeout=10 -rss_limit_mb=2048 \
      -max_total_time="${VIEWLINE_FUZZ_SECONDS:-0}" \
      -artifact_prefix="$findings/" -print_final_stats=1 "$work" >"$log" 2>&1; then
    echo "fuzz/run.sh: $t FAILED (see $log and $findings)" >&2
    status=1
  fi
  end=$(date +%s)
  echo "  $(grep -E '^#[0-9]+[[:space:]]+DONE' "$log" | tail -n1)  wall $((end - start)) s, corpus $(ls "$work" | wc -l) files"
done
exit "$status"
