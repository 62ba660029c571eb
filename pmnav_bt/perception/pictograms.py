"""Reading pictogram plates: a plate that shows a symbol instead of text.

Many buildings mark their toilets with the man / woman / wheelchair pictogram and no
words. OCR reads nothing there, so a toilet goal would never be found by reading. The
plate is still a plate: the sign candidate finder (``signs.SignReader.candidates``)
proposes it like any other, and this reader looks at each candidate the text reader
could not name and says what it shows:

- ``toilet``: the toilet pictogram (the only pictogram the simulator's signage styles
  draw, ``sim/scene/plates.py``; lifts and stairs carry text plates there);
- ``text``: a plate of text;
- ``background``: anything else the finder proposes (a door handle, a rail, clutter).

The reader is a small convolutional network (about 39 k weights, 160 KB) over the
candidate's crop, grey and normalised for brightness and contrast (so a light-on-dark
plate and a dark-on-light one look alike to it), at ``INPUT_H`` x ``INPUT_W`` pixels: the
toilet plate's shape (three figures, twice as wide as high). It was trained in the
simulator on rendered candidate crops of many signage styles, distances, angles and
lights (``pmnav_bt/experiments/pictogram_train.py``, docs/perception.md "Pictograms").
Inference is numpy on the CPU, about a millisecond a plate, in ``einsum``'s own loops
(a BLAS product would wake a pool of threads for a few thousand multiplications): no
torch import.

**Never a false target.** A read is a sighting only when the network is at least
``sighting_p`` sure of a pictogram kind: the threshold was calibrated on development
renders (shipped beside the weights, with how it was chosen). A read short of it that
still leans to a pictogram (``AMBIGUOUS_P``) is *ambiguous*: not a sighting, but a plate
worth reading again from nearer (the grounder remembers it as an unread plate).
"""

from __future__ import annotations

import functools
import json
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from pmnav_bt.errors import BackendError
from pmnav_bt.seams import ImageReading, ReadingView

Box = tuple[float, float, float, float]

CLASSES = ("toilet", "text", "background")
PICTOGRAM_KINDS = ("toilet",)  # the classes that are pictograms (a room kind each)
INPUT_H, INPUT_W = 32, 64  # the toilet plate is twice as wide as high (plates.PICTOGRAM_ASPECT)
PAD = 0.1  # the crop reaches this fraction of the box's height beyond it (the plate's edge)
MIN_BOX_PX = 8  # a candidate lower than this (reading-view pixels) shows no figure
AMBIGUOUS_P = 0.5  # a pictogram this likely, short of the sighting threshold: look again
WEIGHTS = Path(__file__).resolve().parents[1] / "data" / "pictograms.safetensors"


@dataclass(frozen=True)
class PictogramRead:
    """What one candidate shows: the likeliest class, its probability, all of them, and
    whether it is a sighting (a pictogram above the calibrated threshold) or ambiguous."""

    box: Box
    kind: str
    p: float
    probs: tuple[float, ...]
    sighting: bool
    ambiguous: bool


def plate_patch(src: np.ndarray | ReadingView, box: Box) -> np.ndarray | None:
    """The candidate ``box`` of ``src`` (a frame or a reading view, in its pixels), padded
    by ``PAD`` and resized to ``INPUT_H`` x ``INPUT_W`` RGB; None when too small."""
    view = ImageReading(src) if isinstance(src, np.ndarray) else src
    h = box[3] - box[1]
    if h < MIN_BOX_PX or box[2] - box[0] < MIN_BOX_PX:
        return None
    pad = PAD * h
    x0, y0 = int(max(0, box[0] - pad)), int(max(0, box[1] - pad))
    x1, y1 = int(min(view.width, box[2] + pad + 1)), int(min(view.height, box[3] + pad + 1))
    crop = view.crop((x0, y0, x1, y1))
    if crop.size == 0 or crop.shape[0] < 2 or crop.shape[1] < 2:
        return None
    return cv2.resize(np.ascontiguousarray(crop), (INPUT_W, INPUT_H), interpolation=cv2.INTER_AREA)


GREY = np.array([0.299, 0.587, 0.114], np.float32)


def normalise(patches: np.ndarray) -> np.ndarray:
    """(N, H, W, 3) uint8 patches -> (N, 1, H, W) float32: grey, zero mean, unit spread."""
    grey = np.einsum("nhwc,c->nhw", patches.astype(np.float32), GREY)
    mean = grey.mean(axis=(1, 2), keepdims=True)
    std = grey.std(axis=(1, 2), keepdims=True)
    return ((grey - mean) / (std + 8.0))[:, None]


# -- the network (numpy inference; the same layers in torch train it) ----------------------

CONV_CHANNELS = (8, 16, 32)  # three 3x3 convolutions, each followed by ReLU and 2x2 max-pool
HIDDEN = 32


def _conv3x3(x: np.ndarray, w: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Same-padded 3x3 convolution of (N, C, H, W) with (O, C, 3, 3) weights: each pixel's
    3x3 neighbourhood as a row (im2col), times the kernels as one matrix product."""
    n, c, h, wd = x.shape
    xp = np.pad(x, ((0, 0), (0, 0), (1, 1), (1, 1)))
    win = np.lib.stride_tricks.sliding_window_view(xp, (3, 3), axis=(2, 3))  # n,c,h,w,3,3
    cols = win.transpose(0, 2, 3, 1, 4, 5).reshape(n * h * wd, c * 9)
    out = np.einsum("pk,ok->po", cols, w.reshape(len(w), c * 9)) + b  # no BLAS threads
    return out.reshape(n, h, wd, len(w)).transpose(0, 3, 1, 2)


def _pool(x: np.ndarray) -> np.ndarray:
    n, c, h, w = x.shape
    return x.reshape(n, c, h // 2, 2, w // 2, 2).max(axis=(3, 5))


def forward(params: dict[str, np.ndarray], x: np.ndarray) -> np.ndarray:
    """Logits (N, len(CLASSES)) of normalised patches ``x`` (N, 1, INPUT_H, INPUT_W)."""
    for k in range(len(CONV_CHANNELS)):
        x = _pool(np.maximum(_conv3x3(x, params[f"conv{k}.weight"], params[f"conv{k}.bias"]), 0))
    x = x.reshape(len(x), -1)
    x = np.maximum(np.einsum("nk,ok->no", x, params["fc0.weight"]) + params["fc0.bias"], 0)
    return np.einsum("nk,ok->no", x, params["fc1.weight"]) + params["fc1.bias"]


def softmax(logits: np.ndarray) -> np.ndarray:
    z = logits - logits.max(axis=1, keepdims=True)
    e = np.exp(z)
    return e / e.sum(axis=1, keepdims=True)


@functools.lru_cache(maxsize=4)
def _load(path: str) -> tuple[dict[str, np.ndarray], dict]:
    p = Path(path)
    meta_path = p.with_suffix(".json")
    if not p.is_file() or not meta_path.is_file():
        raise BackendError(
            f"pictogram weights not found: {p} (and its .json); train them with "
            "python -m pmnav_bt.experiments.pictogram_train (docs/perception.md)"
        )
    from safetensors.numpy import load_file

    params = {k: v.astype(np.float32) for k, v in load_file(str(p)).items()}
    meta = json.loads(meta_path.read_text(encoding="utf-8"))
    if tuple(meta.get("classes", ())) != CLASSES:
        raise BackendError(f"{meta_path}: classes {meta.get('classes')} are not {list(CLASSES)}")
    return params, meta


class PictogramReader:
    """Says which candidate plates show a pictogram (module docstring).

    ``weights``: a ``.safetensors`` with its ``.json`` (classes, the calibrated
    ``sighting_p``) beside it; default the shipped model. ``sighting_p`` overrides the
    calibrated threshold (tests)."""

    def __init__(self, weights: Path | str = WEIGHTS, sighting_p: float | None = None):
        self.params, self.meta = _load(str(weights))
        self.sighting_p = float(self.meta["sighting_p"] if sighting_p is None else sighting_p)

    def probabilities(self, patches: np.ndarray) -> np.ndarray:
        """Class probabilities (N, len(CLASSES)) of (N, INPUT_H, INPUT_W, 3) patches."""
        if len(patches) == 0:
            return np.zeros((0, len(CLASSES)), np.float32)
        return softmax(forward(self.params, normalise(patches)))

    def read(self, src: np.ndarray | ReadingView, boxes: list[Box]) -> list[PictogramRead]:
        """What each candidate box of ``src`` (its pixels) shows; boxes too small to
        show a figure are left out."""
        kept, patches = [], []
        for box in boxes:
            patch = plate_patch(src, box)
            if patch is not None:
                kept.append(box)
                patches.append(patch)
        if not patches:
            return []
        probs = self.probabilities(np.stack(patches))
        return [self.decide(box, p) for box, p in zip(kept, probs, strict=True)]

    def decide(self, box: Box, probs: np.ndarray) -> PictogramRead:
        """One candidate's read from its class probabilities: a sighting only for a
        pictogram kind at ``sighting_p`` or above; ambiguous for one that is the likeliest
        class, or at least ``AMBIGUOUS_P`` likely, short of it."""
        best = int(np.argmax(probs))
        kind, p = CLASSES[best], float(probs[best])
        picto = max(PICTOGRAM_KINDS, key=lambda k: probs[CLASSES.index(k)])
        pp = float(probs[CLASSES.index(picto)])
        sighting = pp >= self.sighting_p
        ambiguous = not sighting and (kind in PICTOGRAM_KINDS or pp >= AMBIGUOUS_P)
        if sighting or ambiguous:
            kind, p = picto, pp
        return PictogramRead(box, kind, p, tuple(float(v) for v in probs), sighting, ambiguous)
