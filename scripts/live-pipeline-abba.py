#!/usr/bin/env python3
"""The live loop serial against pipelined, side by side in one run (docs/live.md, "Measured").

usage: scripts/live-pipeline-abba.py MIRAGE OUTDIR ROUNDS SCENE... [-- LIVE ARGS...]

For each round and scene, `MIRAGE live` runs twice headless on the bundled sample standing in for
a 30 frames/s camera, 40 frames: A serial (--no-pipeline --no-predict: track, then render, the
pose as tracked) and B pipelined with prediction (the defaults), in ABBA order (A B in odd
rounds, B A in even ones) so that drift of a shared machine falls on both alike. LIVE ARGS
replace the default camera arguments (--camera data/sessions/sample --camera-loop --camera-fps
30). Per run, from its frames.csv over frames 1.. (frame 0 compiles shaders and builds
impostors): frames/s between the first and the last display, medians of the capture-to-display
latency, the interval between displays, the GL thread's frame time, tracking, the hand-off wait
and the prediction's horizon, and how far the pose shown lags the display (latency minus the
horizon); from its log the pose error at display time against the sample's ground truth. The
table goes to stdout and OUTDIR/summary.md. Python standard library only.
"""
import csv
import os
import re
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MODES = {"serial": ["--no-pipeline", "--no-predict"], "pipelined": []}


def summarise(csv_path, log):
    with open(csv_path) as f:
        rows = list(csv.DictReader(f))[1:]
    num = lambda r, k: float(r[k]) if r.get(k, "") != "" else 0.0
    displayed = [num(r, "t") + num(r, "latency_ms") / 1e3 for r in rows]
    lat = [num(r, "latency_ms") for r in rows]
    pred = [num(r, "predict_ms") for r in rows]
    med = statistics.median
    out = {
        "frames/s": (len(rows) - 1) / (displayed[-1] - displayed[0]),
        "latency": med(lat),
        "interval": med([b - a for a, b in zip(displayed, displayed[1:])]) * 1e3,
        "frame": med(num(r, "frame_ms") for r in rows),
        "tracking": med(num(r, "tracking_ms") for r in rows),
        "handoff": med(num(r, "handoff_ms") for r in rows),
        "predict": med(pred),
        "pose lag": med(a - b for a, b in zip(lat, pred)),
    }
    m = re.search(r"ground truth: median ([\d.]+) px \(([\d.]+) mm\) as shown, ([\d.]+) px "
                  r"\(([\d.]+) mm\) without prediction, over (\d+) frames", log)
    out["gt"] = f"{m[1]} / {m[3]} px ({m[5]})" if m else ""
    return out


def main():
    args = sys.argv[1:]
    extra = None
    if "--" in args:
        extra = args[args.index("--") + 1:]
        args = args[:args.index("--")]
    if len(args) < 4:
        print(__doc__)
        return 2
    mirage, outdir, rounds, scenes = args[0], args[1], int(args[2]), args[3:]
    camera = extra if extra is not None else [
        "--camera", os.path.join(ROOT, "data/sessions/sample"), "--camera-loop",
        "--camera-fps", "30"]
    os.makedirs(outdir, exist_ok=True)
    lines = ["| scene | loop | round | frames/s | latency ms | interval ms | latency / interval "
             "| frame ms | tracking ms | hand-off ms | predicted ms ahead | pose lag ms "
             "| error at display: shown / unpredicted px (frames) |",
             "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|"]
    for rnd in range(1, rounds + 1):
        order = ["serial", "pipelined"] if rnd % 2 else ["pipelined", "serial"]
        for scene in scenes:
            for mode in order:
                name = f"{os.path.splitext(os.path.basename(scene))[0]}-{mode}-{rnd}"
                out = os.path.join(outdir, name)
                load = open("/proc/loadavg").read().split()[:3]
                cmd = [mirage, "live", *camera, "--scene", scene, "--headless", "--frames", "40",
                       "-o", out, "--force", *MODES[mode]]
                run = subprocess.run(cmd, capture_output=True, text=True)
                log = run.stdout + run.stderr
                with open(out + ".log", "w") as f:
                    f.write(" ".join(cmd) + "\n" + log)
                if run.returncode != 0:
                    print(f"{name}: failed (exit {run.returncode}), see {out}.log")
                    return 1
                s = summarise(os.path.join(out, "frames.csv"), log)
                lines.append(
                    f"| {os.path.basename(scene)} | {mode} | {rnd} | {s['frames/s']:.2f} "
                    f"| {s['latency']:.0f} | {s['interval']:.0f} "
                    f"| {s['latency'] / s['interval']:.2f} | {s['frame']:.0f} "
                    f"| {s['tracking']:.0f} | {s['handoff']:.0f} | {s['predict']:.0f} "
                    f"| {s['pose lag']:.0f} | {s['gt']} |")
                print(lines[-1] + f" load {' '.join(load)}", flush=True)
    with open(os.path.join(outdir, "summary.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
