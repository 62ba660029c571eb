"""Which characters the project's OCR confuses: the table ``perception/ocr_confusion.py`` reads.

Room codes of every numbering scheme (``map/numbering.py``: 117, 1G, 2.04, L2-204, B117) are
drawn on plates of the simulator's signage styles (``sim/scene/signage.draw_style``: fonts,
colours, plate and capital sizes), shrunk to what a camera sees from afar (capitals
``CAP_PX`` pixels high; half of them nearest-neighbour, as the simulator's renderer
samples), squeezed as seen off the plate's normal (0-70 deg), blurred and noised, set on a
wall-grey frame, and read by the real reader (``SignReader``: the
candidate finder, PP-OCR's detector and recogniser). Each read code line is aligned with
the code drawn (casefolded; an optimal alignment with substitutions, one-character
insertions and deletions, and swaps of two neighbours) and every operation is counted:

- ``correct[c]``, ``substitutions[c][r]``, ``deletions[c]``: what became of a drawn ``c``;
- ``insertions[r]``: characters read that were not drawn; ``transpositions``: swaps;
- ``calibration``: per bin of the recogniser's character confidence, characters read and
  how many were wrong (the recogniser is over-confident on small text: this says by how
  much), in all and per character read (``by_read``: a "1" it is sure of is wrong more
  often than a "7", since I and l are read as 1).

Reads that share nothing with the code (a plate not found, a line cut away) are counted as
``unread`` and not aligned: they say nothing about which characters are confused.

Run: python benchmarks/ocr_confusions.py [--plates 1500] [--seed 0] [--out PATH]
(about 3 min on one core; writes pmnav_bt/data/ocr_confusions.json).
"""

from __future__ import annotations

import argparse
import json
import math
import string
import time
from collections import defaultdict
from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np

from pmnav_bt.map.numbering import SCHEMES, room_code
from pmnav_bt.perception.ocr_confusion import CONFIDENCE_BINS, DATA_FILE, align
from pmnav_bt.perception.signs import SignReader
from pmnav_bt.sim.scene.plates import make_plate, texels_per_m
from pmnav_bt.sim.scene.signage import draw_style

CAP_PX = (3.0, 14.0)  # capital height in the frame: where reading starts to fail
NEAREST_P = 0.5  # views shrunk nearest-neighbour, as the simulator's renderer samples
ANGLE_DEG = (0.0, 70.0)  # off the plate's normal: the plate's width shrinks by cos()
BLUR_SIGMA = (0.0, 1.0)  # pixels: focus and motion
NOISE_SD = (0.0, 6.0)  # grey levels: sensor noise
WALL_RGB = (176, 172, 166)
FRAME = (240, 320)


def draw_code(rng: np.random.Generator) -> str:
    """A code of a random scheme; its wing letter any letter (generated buildings skip I
    and O, other buildings do not: the table must know what becomes of every letter)."""
    scheme = list(SCHEMES)[int(rng.integers(len(SCHEMES)))]
    floor = int(rng.integers(0, 5))
    n = int(rng.integers(1, 40))
    return room_code(scheme, floor, n, string.ascii_uppercase[int(rng.integers(26))])


def view(code: str, rng: np.random.Generator) -> np.ndarray | None:
    """One frame showing a plate of ``code`` in a random signage style and viewing."""
    style = replace(draw_style(rng), layout="number_only", pictogram=None)
    tex = make_plate(code, style)
    cap_texels = style.cap_height * texels_per_m(style.cap_height)
    s = float(rng.uniform(*CAP_PX)) / cap_texels
    sx = s * math.cos(math.radians(float(rng.uniform(*ANGLE_DEG))))
    h, w = tex.image.shape[:2]
    size = (max(1, int(round(w * sx))), max(1, int(round(h * s))))
    if size[0] >= FRAME[1] - 20 or size[1] >= FRAME[0] - 20:
        return None
    nearest = rng.random() < NEAREST_P
    plate = cv2.resize(
        tex.image, size, interpolation=cv2.INTER_NEAREST if nearest else cv2.INTER_AREA
    )
    frame = np.empty((*FRAME, 3), np.float32)
    frame[:] = WALL_RGB
    y0 = int(rng.integers(10, FRAME[0] - size[1] - 10))
    x0 = int(rng.integers(10, FRAME[1] - size[0] - 10))
    frame[y0 : y0 + size[1], x0 : x0 + size[0]] = plate
    sigma = float(rng.uniform(*BLUR_SIGMA))
    if sigma > 0.2:
        frame = cv2.GaussianBlur(frame, (0, 0), sigma)
    frame += rng.normal(0.0, float(rng.uniform(*NOISE_SD)), frame.shape)
    return np.clip(frame, 0, 255).astype(np.uint8)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--plates", type=int, default=1500)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", type=Path, default=DATA_FILE)
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    reader = SignReader()
    correct: dict[str, int] = defaultdict(int)
    subs: dict[str, dict[str, int]] = defaultdict(lambda: defaultdict(int))
    dels: dict[str, int] = defaultdict(int)
    ins: dict[str, int] = defaultdict(int)
    calib = [[0, 0] for _ in CONFIDENCE_BINS]
    by_read: dict[str, list[list[int]]] = defaultdict(lambda: [[0, 0] for _ in CONFIDENCE_BINS])
    transpositions = unread = aligned = 0
    t0 = time.time()
    for _ in range(args.plates):
        code = draw_code(rng)
        frame = view(code, rng)
        if frame is None:
            continue
        lines = [ln for sign in reader.read(frame) for ln in sign.lines]
        if not lines:
            unread += 1
            continue
        line = max(lines, key=lambda ln: len(ln.text))
        read = line.text.casefold().replace(" ", "")
        scores = [s for c, s in zip(line.text, line.char_scores, strict=True) if c != " "]
        ops = align(code.casefold(), read)
        if sum(op[0] == "match" for op in ops) < max(1, len(code) // 2):
            unread += 1
            continue
        aligned += 1
        for kind, drawn, got, j in ops:
            if kind in ("match", "sub"):
                b = int(np.searchsorted(CONFIDENCE_BINS, scores[j], side="right")) - 1
                for cell in (calib[max(b, 0)], by_read[got][max(b, 0)]):
                    cell[0] += 1
                    cell[1] += kind == "sub"
            if kind == "match":
                correct[drawn] += 1
            elif kind == "sub":
                subs[drawn][got] += 1
            elif kind == "del":
                dels[drawn] += 1
            elif kind == "ins":
                ins[got] += 1
            else:
                transpositions += 1
    table = {
        "made_by": "benchmarks/ocr_confusions.py",
        "plates": args.plates,
        "seed": args.seed,
        "aligned": aligned,
        "unread": unread,
        "chars": sum(correct.values()) + sum(sum(v.values()) for v in subs.values()),
        "correct": dict(sorted(correct.items())),
        "substitutions": {k: dict(sorted(v.items())) for k, v in sorted(subs.items())},
        "deletions": dict(sorted(dels.items())),
        "insertions": dict(sorted(ins.items())),
        "transpositions": transpositions,
        "calibration": {
            "bins": list(CONFIDENCE_BINS),
            "read": [c[0] for c in calib],
            "wrong": [c[1] for c in calib],
            "by_read": {
                r: {"read": [c[0] for c in v], "wrong": [c[1] for c in v]}
                for r, v in sorted(by_read.items())
            },
        },
    }
    args.out.write_text(json.dumps(table, indent=1) + "\n")
    errors = sum(sum(v.values()) for v in subs.values()) + sum(dels.values()) + sum(ins.values())
    print(
        f"{args.plates} plates, {aligned} aligned, {unread} unread; {table['chars']} characters, "
        f"{errors} errors, {transpositions} swaps ({time.time() - t0:.0f} s) -> {args.out}"
    )
    top = sorted(((n, f"{d}->{r}") for d, v in subs.items() for r, n in v.items()), reverse=True)
    print("most confused: " + ", ".join(f"{p} {n}" for n, p in top[:15]))


if __name__ == "__main__":
    main()
