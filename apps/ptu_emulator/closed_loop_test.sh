#!/usr/bin/env bash
# The pan-tilt app's closed loop against the emulated FLIR PTU: starts viewline_ptu_emulator on a
# pty or a TCP port, runs pan_tilt_tracking briefly with `robot: {kind: flir_ptu, ...}` (paced to
# the wall clock), and checks that the run finished, tracked the target (image error), issued only
# safe commands, and that the emulator served the commands and received the final halt. Mode
# fault: the emulator stops answering 2 s into the run; the app must stop within its reply
# time-out with exit status 1 and a message naming the port, and a halt must reach the unit.
#
#   closed_loop_test.sh BIN_DIR SOURCE_DIR WORK_DIR tcp|pty|fault
set -euo pipefail
bin=$1 src=$2 work=$3 link=$4
rm -rf "$work" && mkdir -p "$work"
emu_pid=
cleanup() { if [ -n "$emu_pid" ]; then kill -TERM "$emu_pid" 2>/dev/null || true; wait "$emu_pid" 2>/dev/null || true; fi; }
trap cleanup EXIT

if [ "$link" = tcp ]; then
  "$bin/viewline_ptu_emulator" --tcp 0 --endpoints "$work/endpoints" >"$work/emulator.out" 2>&1 &
elif [ "$link" = fault ]; then
  "$bin/viewline_ptu_emulator" --tcp 0 --fault no_reply --fault-after 2 --endpoints "$work/endpoints" \
    >"$work/emulator.out" 2>&1 &
else
  "$bin/viewline_ptu_emulator" --pty --baud 115200 --endpoints "$work/endpoints" >"$work/emulator.out" 2>&1 &
fi
emu_pid=$!
for _ in $(seq 100); do [ -f "$work/endpoints" ] && break; sleep 0.05; done
[ -f "$work/endpoints" ] || { echo "FAIL: the emulator did not start"; cat "$work/emulator.out"; exit 1; }
if [ "$link" != pty ]; then
  robot=(--set robot.kind=flir_ptu --set "robot.tcp=$(sed -n 's/^tcp: //p' "$work/endpoints")")
else
  robot=(--set robot.kind=flir_ptu --set "robot.port=$(sed -n 's/^pty: //p' "$work/endpoints")" --set robot.baud=115200)
fi
cd "$src"
if [ "$link" = fault ]; then
  start=$(date +%s.%N)
  status=0
  "$bin/pan_tilt_tracking" --config config/pan_tilt_circle.yaml --seed 1 --headless --quiet --no-baseline --duration 20 \
    --set camera.fps=15 --set robot.reply_timeout=0.3 "${robot[@]}" --summary "$work/summary.json" >"$work/app.out" 2>&1 || status=$?
  took=$(python3 -c "import sys; print('%.1f' % (float(sys.argv[2]) - float(sys.argv[1])))" "$start" "$(date +%s.%N)")
  kill -TERM "$emu_pid"; wait "$emu_pid" || true; emu_pid=
  cat "$work/app.out" "$work/emulator.out"
  halts=$(sed -n 's/.*(\([0-9]*\) halts).*/\1/p' "$work/emulator.out")
  echo "exit status $status after $took s; halts received: ${halts:-none}"
  [ "$status" = 1 ] || { echo "FAIL: exit status $status, expected 1"; exit 1; }
  grep -q "no reply within 0.3.* s.*127.0.0.1:" "$work/app.out" || { echo "FAIL: no time-out message naming the port"; exit 1; }
  [ "${halts:-0}" -ge 1 ] || { echo "FAIL: no halt reached the unit"; exit 1; }
  python3 -c "import sys; sys.exit(0 if float(sys.argv[1]) < 10.0 else 1)" "$took" || { echo "FAIL: took $took s to stop"; exit 1; }
  echo OK
  exit 0
fi
# 15 frames/s: rendering a 640x480 frame takes 20-50 ms on a loaded 2-core machine, and a run paced
# to the wall clock must keep up with it.
# --record: the session a user records on the unit to tune on (viewline_tune --recording): every
# frame, and ptu.csv with the unit's joint readings per frame.
"$bin/pan_tilt_tracking" --config config/pan_tilt_circle.yaml --seed 1 --headless --quiet --no-baseline --duration 3 \
  --set run.metrics_start=1 --set camera.fps=15 "${robot[@]}" --summary "$work/summary.json" --record "$work/rec" \
  >"$work/app.out" 2>&1 ||
  { echo "FAIL: pan_tilt_tracking failed"; cat "$work/app.out"; exit 1; }
kill -TERM "$emu_pid"; wait "$emu_pid" || true; emu_pid=
cat "$work/app.out" "$work/emulator.out"
python3 - "$work/summary.json" "$work/emulator.out" "$work/rec" <<'PY'
import csv, glob, json, math, re, sys
s = json.load(open(sys.argv[1]))
ours = s["ours"]
served = re.search(r"served (\d+) commands \((\d+) halts\)", open(sys.argv[2]).read())
problems = []
if ours["frames"] != 45: problems.append(f"frames {ours['frames']} != 45")
# Paced to the wall clock, the loop tracks only while each frame's rendering, detection and
# exchanges take about the frame period: a frame that takes longer delays every later one while the
# unit moves on in real time. Measured here: 83 ms and 104 ms per frame against the 66.7 ms period
# still tracked (15 and 23 px), 134 ms lost the target. Beyond 1.75 periods per frame (a machine too
# loaded to keep real time) the tracking check says so instead of failing; the protocol checks
# below always apply.
period_ms = 1000.0 / s["camera"]["fps"]
if ours["wall_ms_per_frame"] <= 1.75 * period_ms:
    if ours["detections"] < 40: problems.append(f"only {ours['detections']} detections of 45 frames")
    if not ours["image_error_rms_px"] < 40.0: problems.append(f"image error rms {ours['image_error_rms_px']:.1f} px >= 40 px: not tracking")
else:
    print(f"tracking not checked: {ours['wall_ms_per_frame']:.1f} ms per frame, over 1.75 periods of {period_ms:.1f} ms (machine too loaded to keep real time)")
if s["commands_outside_limits"] != 0: problems.append(f"{s['commands_outside_limits']} unsafe commands")
if not served: problems.append("the emulator did not report")
else:
    # Start-up (15), the move to the start (5), a command and reads per frame, the final halt.
    if int(served.group(1)) < 100: problems.append(f"the emulator served only {served.group(1)} commands")
    if int(served.group(2)) < 1: problems.append("no halt reached the emulator")
# The recording holds the unit's own readings: one ptu.csv row per frame, joints that moved, within
# the unit's range (the emulator's read-back, not the simulator's state).
tables = glob.glob(sys.argv[3] + "/*/ptu.csv")
if len(tables) != 1: problems.append(f"expected one ptu.csv in the recording, found {tables}")
else:
    rows = list(csv.DictReader(open(tables[0])))
    frames = glob.glob(sys.argv[3] + "/*/cam0/*.png")
    if len(rows) != ours["frames"] or len(frames) != ours["frames"]:
        problems.append(f"ptu.csv rows {len(rows)}, frames {len(frames)}, run frames {ours['frames']}")
    if rows:
        pan = [float(r["pan"]) for r in rows]
        tilt = [float(r["tilt"]) for r in rows]
        if not all(math.isfinite(x) and abs(x) < math.radians(160) for x in pan + tilt):
            problems.append("ptu.csv joints not finite or outside the unit's range")
        if max(pan) - min(pan) < math.radians(0.5): problems.append("ptu.csv: the pan reading never moved")
        print(f"recording: {len(rows)} ptu.csv rows, pan {math.degrees(min(pan)):.2f}..{math.degrees(max(pan)):.2f} deg")
print("image error rms %.2f px, %d detections; %s" % (ours["image_error_rms_px"], ours["detections"], served.group(0) if served else "-"))
if problems:
    print("FAIL: " + "; ".join(problems)); sys.exit(1)
print("OK")
PY
