#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Image processing in the loop: a camera image -> the target's centroid -> setpoints.

The non-real-time side of the thesis' setups (image processing on the planner board)
in a few lines: each period it takes an image (here a synthetic one: a bright blob
moving on a circle, with noise), finds the blob's centroid, and publishes the
centroid's offset from the image centre, scaled to metres, as the base position
setpoints (base_x_sp, base_y_sp of dist/signals.xml). The control board's loop reads
them and falls back to its safe value if this script stops.

    python3 centroid_setpoints.py --node planner --rate 50

Needs ccommd running for the node, and numpy.
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from typing import Dict, List, Optional, Tuple

import numpy as np
import numpy.typing as npt

import ccomm

Image = npt.NDArray[np.float64]


def synthetic_image(t: float, size: int = 96, rng: Optional[np.random.Generator] = None,
                    radius_px: float = 25.0, period_s: float = 4.0) -> Tuple[Image, Tuple[float, float]]:
    """A camera stand-in: Gaussian blob on a circle plus noise. Returns the image and
    the blob's true centre (x, y) in pixels."""
    c = (size - 1) / 2.0
    phase = 2.0 * math.pi * t / period_s
    bx, by = c + radius_px * math.cos(phase), c + radius_px * math.sin(phase)
    y, x = np.mgrid[0:size, 0:size].astype(np.float64)
    img = np.exp(-((x - bx) ** 2 + (y - by) ** 2) / (2.0 * 4.0 ** 2))
    if rng is not None:
        img += rng.normal(0.0, 0.03, img.shape)
    return img, (bx, by)


def centroid(img: Image, threshold: float = 0.3) -> Optional[Tuple[float, float]]:
    """Intensity-weighted centre (x, y) of the pixels above `threshold`; None if none."""
    w = np.where(img > threshold, img, 0.0)
    total = float(w.sum())
    if total <= 0.0:
        return None
    ys, xs = np.indices(img.shape)
    return float((w * xs).sum() / total), float((w * ys).sum() / total)


def run(node: Optional[str], rate_hz: float, duration_s: float, metres_per_px: float,
        x_signal: str = "base_x_sp", y_signal: str = "base_y_sp", seed: int = 1) -> Dict[str, float]:
    """The loop; returns counters. Stops after duration_s (0 = until Ctrl-C)."""
    rng = np.random.default_rng(seed)
    errors: List[float] = []
    published = lost_target = 0
    with ccomm.Client(node) as c:
        sx, sy = c.signal(x_signal), c.signal(y_signal)
        period = 1.0 / rate_hz
        start = next_t = time.monotonic()
        try:
            while duration_s <= 0 or time.monotonic() - start < duration_s:
                t = time.monotonic() - start
                img, (tx, ty) = synthetic_image(t, rng=rng)
                cen = centroid(img)
                if cen is None:
                    lost_target += 1  # publish nothing: the setpoints go stale, the robot stops
                else:
                    cx, cy = cen
                    errors.append(math.hypot(cx - tx, cy - ty))
                    half = (img.shape[1] - 1) / 2.0
                    sx.write((cx - half) * metres_per_px)
                    sy.write((cy - half) * metres_per_px)
                    published += 1
                next_t += period
                time.sleep(max(0.0, next_t - time.monotonic()))
        except KeyboardInterrupt:
            pass
    return {"published": published, "lost_target": lost_target,
            "max_centroid_error_px": max(errors) if errors else float("nan")}


def main(argv: Optional[List[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--node", help="ccomm node (default: $CCOMM_NODE, else the hostname)")
    ap.add_argument("--rate", type=float, default=50.0, help="frames per second (default 50)")
    ap.add_argument("--duration", type=float, default=0.0, help="seconds to run (default: until Ctrl-C)")
    ap.add_argument("--scale", type=float, default=0.01, help="metres per pixel (default 0.01)")
    ap.add_argument("--x-signal", default="base_x_sp")
    ap.add_argument("--y-signal", default="base_y_sp")
    a = ap.parse_args(argv)
    try:
        stats = run(a.node, a.rate, a.duration, a.scale, a.x_signal, a.y_signal)
    except ccomm.CcommError as e:
        print(f"centroid_setpoints: {e}", file=sys.stderr)
        return 1
    print(f"published {stats['published']} setpoint pairs, target lost in {stats['lost_target']} frames, "
          f"worst centroid error {stats['max_centroid_error_px']:.2f} px")
    return 0


if __name__ == "__main__":
    sys.exit(main())
