#!/usr/bin/env python3
"""A live run's composites against the same recording replayed at full quality (docs/live.md).

usage: scripts/live-replay-psnr.py LIVE_DIR RECORDING REPLAY_DIR

LIVE_DIR holds `mirage live -o LIVE_DIR --record RECORDING`'s PNG frames, REPLAY_DIR those of
`mirage replay RECORDING --scene SCENE --poses RECORDING/poses.csv -o REPLAY_DIR` (no budget: full
quality). Per frame the mask is the pixels the renderer changed: where the live composite differs
from the recording's footage (RECORDING/main.mkv) by more than 2/255 in a channel (the
recording's JPEG noise is in the mask and counts as error). Prints the PSNR of the replay against
the live composite pooled over every frame's mask, and the worst frame's. Needs the Debian
packages python3-opencv and python3-numpy (`apt-get install python3-opencv`); the build and the
tests do not.
"""
import glob
import math
import os
import sys

import cv2
import numpy as np


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    live, recording, replay = sys.argv[1:4]
    video = os.path.join(recording, "main.mkv")
    capture = cv2.VideoCapture(video)
    if not capture.isOpened():
        sys.exit(f"{video}: cannot be read (is RECORDING a `mirage live --record` folder?)")
    frames = sorted(glob.glob(os.path.join(live, "frame_*.png")))
    if not frames:
        sys.exit(f"{live}: no frame_*.png (was `mirage live -o` given a folder?)")
    squared, count, worst = 0.0, 0, math.inf
    for path in frames:
        ok, footage = capture.read()
        if not ok:
            break
        other = os.path.join(replay, os.path.basename(path))
        if not os.path.exists(other):
            sys.exit(f"{other}: missing (the replay wrote fewer frames than the live run)")
        a = cv2.imread(path).astype(np.float64)
        b = cv2.imread(other).astype(np.float64)
        mask = np.abs(a - footage.astype(np.float64)).max(axis=2) > 2.0
        if not mask.any():
            continue
        e = ((a - b) ** 2)[mask]
        squared += e.sum()
        count += e.size
        worst = min(worst, 10.0 * math.log10(255.0**2 / max(e.mean(), 1e-12)))
    if count == 0:
        sys.exit("no pixel changed by the renderer in any frame")
    pooled = 10.0 * math.log10(255.0**2 / max(squared / count, 1e-12))
    print(f"{pooled:.2f} dB pooled over {count // 3} pixels of {len(frames)} frames; "
          f"worst frame {worst:.2f} dB")


if __name__ == "__main__":
    main()
