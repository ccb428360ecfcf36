#!/usr/bin/env bash
# The pan-tilt loop on the simulated unit and on the emulated FLIR PTU (TCP, pty at 115200 and 9600
# baud emulated), same config and seeds: circle path, 15 frames/s, ours only, metrics after 2 s.
# The emulated drive gets the simulated unit's 30 ms command latency (--drive-latency), so that
# what differs is the protocol (its exchanges) and the wall clock (the run is paced to it).
# Prints one line per run and the mean and standard deviation of the image error per mode.
#
#   bench/ptu/closed_loop_study.sh [SEEDS] [DURATION_S]     (default 5 seeds, 10 s; run from the repository root)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
bin="${VIEWLINE_BUILD_DIR:-$root/build}/bin"
seeds=${1:-5} duration=${2:-10}
work=$(mktemp -d)
emu_pid=
cleanup() { if [ -n "$emu_pid" ]; then kill -TERM "$emu_pid" 2>/dev/null || true; wait "$emu_pid" 2>/dev/null || true; fi; rm -rf "$work"; }
trap cleanup EXIT
cd "$root"
common=(--config config/pan_tilt_circle.yaml --headless --quiet --no-baseline --duration "$duration"
        --set run.metrics_start=2 --set camera.fps=15)

start_emulator() {  # start_emulator ARGS...: serves until killed
  rm -f "$work/endpoints"
  "$bin/viewline_ptu_emulator" "$@" --drive-latency 0.03 --endpoints "$work/endpoints" >"$work/emulator.out" 2>&1 &
  emu_pid=$!
  for _ in $(seq 100); do [ -f "$work/endpoints" ] && return 0; sleep 0.05; done
  echo "the emulator did not start" >&2; exit 1
}
stop_emulator() { kill -TERM "$emu_pid"; wait "$emu_pid" || true; emu_pid=; }

run_mode() {  # run_mode NAME ROBOT_ARGS...
  local name=$1; shift
  for seed in $(seq 1 "$seeds"); do
    "$bin/pan_tilt_tracking" "${common[@]}" --seed "$seed" "$@" --summary "$work/$name.$seed.json" >/dev/null
    python3 -c "import json,sys; s=json.load(open(sys.argv[1]))['ours']; print('%-22s seed %d  image error rms %7.2f px  max %7.2f px  %6.1f ms/frame' % (sys.argv[2], int(sys.argv[3]), s['image_error_rms_px'], s['image_error_max_px'], s['wall_ms_per_frame']))" \
      "$work/$name.$seed.json" "$name" "$seed"
  done
}

run_mode simulated
start_emulator --tcp 0
run_mode emulator_tcp --set robot.kind=flir_ptu --set "robot.tcp=$(sed -n 's/^tcp: //p' "$work/endpoints")"
stop_emulator
for baud in 115200 9600; do
  start_emulator --pty --baud "$baud"
  run_mode "emulator_pty_$baud" --set robot.kind=flir_ptu --set "robot.port=$(sed -n 's/^pty: //p' "$work/endpoints")" \
    --set robot.baud="$baud"
  stop_emulator
done
python3 - "$work" <<'PY'
import glob, json, os, statistics, sys
modes = {}
for f in sorted(glob.glob(os.path.join(sys.argv[1], "*.json"))):
    name = os.path.basename(f).split(".")[0]
    s = json.load(open(f))["ours"]
    modes.setdefault(name, []).append((s["image_error_rms_px"], s["wall_ms_per_frame"], s["detections"], s["frames"]))
print("%-22s %5s %22s %18s %12s" % ("mode", "runs", "image error rms (px)", "wall ms/frame", "detections"))
for name in ["simulated", "emulator_tcp", "emulator_pty_115200", "emulator_pty_9600"]:
    r = modes.get(name, [])
    if not r: continue
    e = [x[0] for x in r]; w = [x[1] for x in r]
    sd = statistics.stdev(e) if len(e) > 1 else 0.0
    print("%-22s %5d %12.2f ± %6.2f %10.1f ± %5.1f %7d/%d" % (name, len(r), statistics.mean(e), sd, statistics.mean(w),
          statistics.stdev(w) if len(w) > 1 else 0.0, sum(x[2] for x in r), sum(x[3] for x in r)))
PY
