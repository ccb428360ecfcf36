#!/usr/bin/env python3
"""Command-line failure classes for every executable of build/bin, one case per (executable, class).

Each case runs the executable with one bad input and checks:
  * the exit status: 2 for a usage error (missing or directory file, a value of the wrong type, contradictory
    or unknown flags), 1 for a runtime error (a file that exists but cannot be read as what it should be);
  * no crash (killed by a signal) and no hang (60 s);
  * a message on stderr naming the problem (the file, or the flag);
  * no output file: the output paths the command line names do not exist afterwards.
Interrupt cases run a long scenario, send SIGINT or SIGTERM after about 1 s and check the exit status
(130 / 143), that the summary is written with "interrupted": true, and that the process is gone.

  cli_test.py --list                      the case names (ctest registers one test each)
  cli_test.py --bin DIR --source DIR --work DIR CASE
"""
import argparse
import json
import os
import shutil
import signal
import subprocess
import sys
import time

TIMEOUT_S = 60

# Usage-error classes exit 2, runtime-error classes exit 1.
CLASSES = {
    "missing_file": 2,
    "directory": 2,
    "empty_file": 1,
    "binary_file": 1,
    "wrong_type": 2,
    "contradictory": 2,
    "unknown_flag": 2,
}

SCENARIO_APPS = {
    # name: (config, extra args of a short valid run, the flag whose value gets the wrong type, long-run args)
    "dart_tracking": ("config/dart_tracking.yaml", ["--runs", "1"], "--runs", ["--runs", "100000"]),
    "ball_catching": ("config/ball_catching.yaml", ["--throws", "1"], "--throws", ["--throws", "100000"]),
    "pan_tilt_tracking": ("config/pan_tilt_circle.yaml", ["--duration", "1", "--set", "run.metrics_start=0.5"], "--seed",
                          ["--duration", "100000"]),
    "table_ball_balancing": ("config/table_ball.yaml", ["--duration", "0.5"], "--duration", ["--duration", "100000"]),
    "mobile_capture": ("config/mobile_capture.yaml", ["--runs", "1"], "--runs", ["--runs", "40"]),
}


# Apps with --record DIR / --replay DIR: a recording is never written into a folder that is not new
# and empty (exit 1, the folder untouched), nor where no folder can be made (exit 1); --replay of a
# folder that does not exist is a usage error (exit 2). Each message names the folder.
RECORD_APPS = ["ball_catching", "mobile_capture", "dart_tracking"]
RECORD_CLASSES = {"record_nonempty": 1, "record_unwritable": 1, "replay_missing": 2}

# Apps that run on footage (source: images|video|v4l2): a pattern whose first image is missing, a
# video that does not exist and a pattern with two conversions are runtime errors (exit 1) whose
# message names the file or the pattern, and no summary is written.
FOOTAGE_APPS = ["table_ball_balancing"]
FOOTAGE_CLASSES = {"footage_missing_image": 1, "footage_missing_video": 1, "footage_bad_pattern": 1}


def table():
    """executable -> dict(file=(flag or None for a positional, rest of the command line), outputs, wrong_type,
    contradictory, expected-status overrides)."""
    t = {}
    for app, (cfg, short, typed, _) in SCENARIO_APPS.items():
        t[app] = dict(
            file=("--config", short + ["--quiet"]),
            outputs=["--summary", "{out}/summary.json", "--log", "{out}/log"],
            wrong_type=[typed, "abc", "--config", cfg],
            contradictory=["--config", cfg, "--headless", "--display"],
            valid=["--config", cfg] + short,
        )
    t["pan_tilt_tracking"]["contradictory"] = ["--config", "config/pan_tilt_circle.yaml", "--replay", "config/pan_tilt_circle.yaml",
                                               "--oracle-corners", "--particles"]
    t["viewline_demo"] = dict(file=None, outputs=[], wrong_type=["--runs", "abc"], contradictory=None, valid=["--runs", "1"])
    # viewline_tune documents bad input in a file (a sweep's key, a scenario's value) as a usage error: exit 2.
    t["viewline_tune"] = dict(
        prefix=["run"],
        file=("--config", ["--scenario", "dart", "--quiet"]),
        outputs=["--out", "{out}/tune"],
        wrong_type=["--scenario", "dart", "--config", "config/dart_tracking.yaml", "--seed", "abc"],
        contradictory=["--scenario", "dart", "--config", "config/dart_tracking.yaml", "--headless", "--display"],
        status={"empty_file": 2, "binary_file": 2},
        valid=["--scenario", "dart", "--config", "config/dart_tracking.yaml"],
    )
    board = "calib/boards/opencv_chessboard_9x6.yaml"
    xml = "calib/rigs/pan_tilt/intrinsics/ptu_camera.xml"
    image = "docs/pictures/pan_tilt_display.png"
    t["calibrate-camera"] = dict(file=("--board", [image]), outputs=["--output-xml", "{out}/c.xml", "--report", "{out}/r.json"],
                                 wrong_type=["--board", board, "--min-views", "abc", image],
                                 contradictory=None, valid=["--board", board, image])
    t["compute-board-poses"] = dict(file=("--board", ["--intrinsics", xml, "--camera-name", "ptu_camera", image]),
                                    outputs=["--output", "{out}/poses.yaml"], wrong_type=None, contradictory=None,
                                    valid=["--board", board, "--intrinsics", xml, image])
    t["calibrate-rig"] = dict(file=("--config", []), outputs=["--output", "{out}/rig.yaml"], wrong_type=None, contradictory=None,
                              valid=["--config", board])
    t["calibrate-hand-eye"] = dict(file=("--robot-poses", ["--camera-poses", "calib/rigs/pan_tilt/e_M_c.yaml"]),
                                   outputs=["--output", "{out}/he.yaml"],
                                   wrong_type=["--robot-poses", board, "--camera-poses", board, "--rig-pose", "abc"],
                                   contradictory=["--robot-poses", board, "--camera-poses", board, "--rig-output", "{out}/rig.yaml"],
                                   valid=["--robot-poses", board, "--camera-poses", board])
    t["camera-to-ground"] = dict(file=("--board", ["--intrinsics", xml, image]), outputs=["--output", "{out}/g.yaml"],
                                 wrong_type=["--board", board, "--intrinsics", xml, "--tag-id", "abc", image],
                                 contradictory=None, valid=["--board", board, "--intrinsics", xml, image])
    t["render-board-views"] = dict(file=("--truth", ["--board", board]), outputs=["--output-dir", "{out}/views"],
                                   wrong_type=["--truth", "calib/rigs/pan_tilt/truth.yaml", "--board", board, "--views", "abc"],
                                   contradictory=None, valid=["--truth", "calib/rigs/pan_tilt/truth.yaml", "--board", board])
    t["check-rig-calibration"] = dict(file=("--truth", ["--rig", "calib/rigs/pan_tilt/rig.yaml"]), outputs=[],
                                      wrong_type=["--truth", "calib/rigs/pan_tilt/truth.yaml", "--rig", "calib/rigs/pan_tilt/rig.yaml",
                                                  "--max-ray-px", "abc"],
                                      contradictory=None,
                                      valid=["--truth", "calib/rigs/pan_tilt/truth.yaml", "--rig", "calib/rigs/pan_tilt/rig.yaml"])
    t["print-board"] = dict(file=("--board", []), outputs=["--output", "{out}/b.png", "--pdf", "{out}/b.pdf"],
                            wrong_type=["--board", board, "--dpi", "abc"], contradictory=None, valid=["--board", board])
    # load_rig, a tutorial's 40-line program, takes the rig file as its argument and reports every
    # problem with it (missing, a directory, unreadable) as a runtime error.
    t["load_rig"] = dict(file=(None, []), outputs=[], wrong_type=None, contradictory=None, valid=[],
                         status={"missing_file": 1, "directory": 1})
    t["tutorial-picture"] = dict(file=("--input", []), outputs=["--output", "{out}/p.png"],
                                 wrong_type=["--input", image, "--width", "abc"], contradictory=None, valid=["--input", image])
    return t


def cases():
    out = []
    for exe, spec in table().items():
        for cls in CLASSES:
            if cls in ("missing_file", "directory", "empty_file", "binary_file") and spec["file"] is None:
                continue
            if cls in ("wrong_type", "contradictory") and spec[cls] is None:
                continue
            out.append(f"{exe}.{cls}")
    for app in SCENARIO_APPS:
        out += [f"{app}.full_disk_summary", f"{app}.sigint", f"{app}.sigterm"]
    out.append("dart_tracking.full_disk_log")
    for app in RECORD_APPS:
        out += [f"{app}.{cls}" for cls in RECORD_CLASSES]
    for app in FOOTAGE_APPS:
        out += [f"{app}.{cls}" for cls in FOOTAGE_CLASSES]
    return out


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def fmt(args, out):
    return [a.replace("{out}", out) for a in args]


def leftovers(out):
    found = []
    for root, dirs, files in os.walk(out):
        found += [os.path.join(root, f) for f in files]
        found += [os.path.join(root, d) for d in dirs if not os.listdir(os.path.join(root, d))]
    return found


def run_failing(cmd, expected, what):
    """Runs cmd (no hang within TIMEOUT_S), prints it and its output, and fails unless it exited with
    `expected` (not a signal). Returns the completed process for the case's own checks."""
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, errors="replace", timeout=TIMEOUT_S)
    except subprocess.TimeoutExpired:
        fail(f"hang: no exit within {TIMEOUT_S} s: {' '.join(cmd)}")
    print("$ " + " ".join(cmd))
    print(f"exit {p.returncode}\n--- stderr\n{p.stderr[-3000:]}\n--- stdout\n{p.stdout[-1000:]}")
    if p.returncode < 0:
        fail(f"crash: killed by signal {-p.returncode}")
    if p.returncode != expected:
        fail(f"exit status {p.returncode}, expected {expected} ({what})")
    return p


def run_case(exe, cls, binary, work):
    spec = table()[exe]
    out = os.path.join(work, "out")
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(out)
    bad = {
        "missing_file": os.path.join(work, "no_such_file.yaml"),
        "directory": os.path.join(work, "a_directory"),
        "empty_file": os.path.join(work, "empty.yaml"),
        "binary_file": os.path.join(work, "binary.yaml"),
    }
    os.makedirs(bad["directory"])
    open(bad["empty_file"], "wb").close()
    with open(bad["binary_file"], "wb") as f:
        f.write(bytes(range(256)) * 16 + b"\x00\xff\xfe\x89PNG\r\n\x1a\n")
    expected = spec.get("status", {}).get(cls, CLASSES[cls])
    if cls in bad:
        flag, rest = spec["file"]
        args = ([flag] if flag else []) + [bad[cls]] + rest
        named = [bad[cls], os.path.basename(bad[cls])]
    elif cls == "wrong_type":
        args = list(spec["wrong_type"])
        named = ["abc", args[args.index("abc") - 1]]
    elif cls == "contradictory":
        args = list(spec["contradictory"])
        named = [a for a in args if a.startswith("--") and a not in ("--config", "--scenario", "--board", "--robot-poses",
                                                                      "--camera-poses")]
    else:
        args = ["--no-such-flag"] + fmt(spec["valid"], out)
        named = ["--no-such-flag"]
    args = fmt(spec.get("prefix", []) + args + spec["outputs"], out)
    if exe == "load_rig" and cls == "unknown_flag":
        args = ["--no-such-flag", "calib/rigs/dart/rig.yaml"]
    cmd = [binary] + args
    p = run_failing(cmd, expected, cls)
    text = p.stderr + p.stdout
    if not any(n in text for n in named):
        fail(f"the message names none of {named}")
    left = leftovers(out)
    if left:
        fail(f"output written although the command failed: {left}")
    print("ok")


def run_interrupt(app, sig, binary, work):
    cfg, _, _, long_args = SCENARIO_APPS[app]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    summary = os.path.join(work, "summary.json")
    cmd = [binary, "--config", cfg, "--quiet", "--summary", summary, "--log", os.path.join(work, "log")] + long_args
    print("$ " + " ".join(cmd))
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, errors="replace")
    # The signal handler exists once main() runs (loading ViSP and OpenCV can take seconds on a busy
    # machine): wait until the run has made its log folder (after the config is read), then 1 s more.
    log_dir = os.path.join(work, "log")
    t_wait = time.monotonic()
    while not os.path.isdir(log_dir) and p.poll() is None and time.monotonic() - t_wait < TIMEOUT_S:
        time.sleep(0.05)
    time.sleep(1.0)
    if p.poll() is not None:
        fail(f"ended before the signal (exit {p.returncode}): {p.stderr.read()[-2000:]}")
    t0 = time.monotonic()
    p.send_signal(sig)
    try:
        stdout, stderr = p.communicate(timeout=TIMEOUT_S)
    except subprocess.TimeoutExpired:
        p.kill()
        p.communicate()
        fail(f"still running {TIMEOUT_S} s after the signal (killed)")
    stop_s = time.monotonic() - t0
    print(f"exit {p.returncode} {stop_s:.2f} s after the signal\n--- stderr\n{stderr[-2000:]}\n--- stdout\n{stdout[-1000:]}")
    expected = 128 + sig
    if p.returncode != expected:
        fail(f"exit status {p.returncode}, expected {expected}")
    if not os.path.exists(summary):
        fail("no summary written")
    with open(summary) as f:
        j = json.load(f)
    if j.get("interrupted") is not True:
        fail('the summary does not say "interrupted": true')
    name = "SIGINT" if sig == signal.SIGINT else "SIGTERM"
    if j.get("interrupt_signal") != name:
        fail(f'interrupt_signal is {j.get("interrupt_signal")!r}, expected {name}')
    stray = [f for f in os.listdir(work) if ".tmp" in f]
    if stray:
        fail(f"temporary files left: {stray}")
    print(f"ok: stopped {stop_s:.2f} s after {name}")


def run_record_case(app, cls, binary, work):
    cfg, short, _, _ = SCENARIO_APPS[app]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    summary = os.path.join(work, "summary.json")
    if cls == "record_nonempty":
        folder = os.path.join(work, "rec")
        os.makedirs(folder)
        with open(os.path.join(folder, "keep.txt"), "w") as f:
            f.write("not a recording\n")
        flag = ["--record", folder]
    elif cls == "record_unwritable":
        # Under a regular file no folder can be made, whoever runs the test (root ignores permissions).
        with open(os.path.join(work, "a_file"), "w") as f:
            f.write("x\n")
        folder = os.path.join(work, "a_file", "rec")
        flag = ["--record", folder]
    else:
        folder = os.path.join(work, "no_such_recording")
        flag = ["--replay", folder]
    cmd = [binary, "--config", cfg, "--quiet", "--summary", summary] + short + flag
    p = run_failing(cmd, RECORD_CLASSES[cls], cls)
    if folder not in p.stderr:
        fail(f"the message does not name {folder}")
    if os.path.exists(summary):
        fail("a summary was written although the run failed")
    if cls == "record_nonempty" and os.listdir(folder) != ["keep.txt"]:
        fail(f"the existing folder was written into: {os.listdir(folder)}")
    print("ok")


def run_footage_case(app, cls, binary, work):
    cfg, _, _, _ = SCENARIO_APPS[app]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    summary = os.path.join(work, "summary.json")
    if cls == "footage_missing_image":
        source = "{kind: images, pattern: " + os.path.join(work, "no_frames", "image.%04d.png") + "}"
        named = os.path.join(work, "no_frames", "image.0000.png")
    elif cls == "footage_missing_video":
        named = os.path.join(work, "none.avi")
        source = "{kind: video, path: " + named + "}"
    else:
        named = os.path.join(work, "a%d_%d.png")
        source = "{kind: images, pattern: " + named + "}"
    cmd = [binary, "--config", cfg, "--quiet", "--summary", summary, "--set", "source=" + source]
    p = run_failing(cmd, FOOTAGE_CLASSES[cls], cls)
    if named not in p.stderr:
        fail(f"the message does not name {named}")
    if os.path.exists(summary):
        fail("a summary was written although the run failed")
    print("ok")


SKIP = 77  # ctest's SKIP_RETURN_CODE for these tests


def run_full_disk(app, what, binary, work):
    """A full disk, for real: a 64 KiB tmpfs mounted in a private mount namespace (unshare -r -m: no
    privileges needed where user namespaces are allowed), filled up before the run ("summary") or
    left to fill with the run's CSV logs ("log"). The app must exit 1 naming the file and the cause,
    and leave no summary and no temporary behind."""
    cfg, short, _, _ = SCENARIO_APPS[app]
    shutil.rmtree(work, ignore_errors=True)
    mnt = os.path.join(work, "mnt")
    os.makedirs(mnt)
    probe = subprocess.run(["unshare", "-r", "-m", "sh", "-c", f"mount -t tmpfs -o size=64k none '{mnt}'"],
                           capture_output=True, text=True)
    if probe.returncode != 0:
        print(f"SKIP: cannot mount a small tmpfs here (unshare -r -m: {probe.stderr.strip()})")
        sys.exit(SKIP)
    summary = os.path.join(mnt, "summary.json")
    args = ["--config", cfg, "--quiet", "--summary", summary]
    args += short if what == "summary" else ["--log", os.path.join(mnt, "log"), "--runs", "20"]
    fill = f"dd if=/dev/zero of='{mnt}/filler' bs=4096 2>/dev/null;" if what == "summary" else ""
    listing = os.path.join(work, "listing")
    script = (f"mount -t tmpfs -o size=64k none '{mnt}' || exit 99; {fill} \"$@\"; rc=$?; "
              f"find '{mnt}' -mindepth 1 -printf '%P\\n' > '{listing}'; exit $rc")
    cmd = ["unshare", "-r", "-m", "sh", "-c", script, "sh", binary] + args
    print("$ " + " ".join(cmd))
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, errors="replace", timeout=TIMEOUT_S)
    except subprocess.TimeoutExpired:
        fail(f"hang: no exit within {TIMEOUT_S} s")
    print(f"exit {p.returncode}\n--- stderr\n{p.stderr[-3000:]}\n--- stdout\n{p.stdout[-500:]}")
    if p.returncode == 99:
        fail("the tmpfs could not be mounted in the namespace")
    if p.returncode != 1:
        fail(f"exit status {p.returncode}, expected 1 (a runtime error)")
    if "No space left on device" not in p.stderr:
        fail("the message does not say the disk is full")
    named = summary if what == "summary" else os.path.join(mnt, "log")
    if named not in p.stderr:
        fail(f"the message does not name {named}")
    with open(listing) as f:
        left = [l for l in f.read().split() if l]
    print("left on the full disk: " + " ".join(left))
    if "summary.json" in left:
        fail("a summary was written although the run failed")
    stray = [l for l in left if ".tmp" in l]
    if stray:
        fail(f"temporary files left: {stray}")
    print("ok")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--list", action="store_true")
    ap.add_argument("--bin")
    ap.add_argument("--source")
    ap.add_argument("--work")
    ap.add_argument("case", nargs="?")
    a = ap.parse_args()
    if a.list:
        print(";".join(cases()))
        return
    exe, cls = a.case.rsplit(".", 1)
    binary = os.path.join(a.bin, exe)
    if not os.path.exists(binary):
        fail(f"{binary} not built")
    os.chdir(a.source)  # the configs and calibration files the command lines name are relative to the checkout
    if cls.startswith("full_disk_"):
        run_full_disk(exe, cls[len("full_disk_"):], binary, a.work)
    elif cls in RECORD_CLASSES:
        run_record_case(exe, cls, binary, a.work)
    elif cls in FOOTAGE_CLASSES:
        run_footage_case(exe, cls, binary, a.work)
    elif cls in ("sigint", "sigterm"):
        run_interrupt(exe, signal.SIGINT if cls == "sigint" else signal.SIGTERM, binary, a.work)
    else:
        run_case(exe, cls, binary, a.work)


if __name__ == "__main__":
    main()
