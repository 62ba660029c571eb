"""The last frame perception looked at, and what it found there: for the web view.

:class:`FrameTap` wraps a ``Grounder`` and passes every call through unchanged. After a
``detect`` or ``read_signs`` it keeps the frame, shrunk to a JPEG of ``FRAME_WIDTH``
pixels, with the detections and signs read (boxes in the JPEG's pixels, label,
score, entity). Both calls on one frame (a panorama view grounds the target and reads
its signs) make one :class:`TappedFrame`.

The JPEG is made here, in the thread that called the grounder: on the worker, beside
a reading that costs tens of milliseconds, never in a tick (docs/architecture.md, a
tick never blocks). The tree log's writer takes the newest frame between ticks
(:meth:`FrameTap.take`). 320 pixels show where a sign or a door was found; the text
read is logged beside the picture, so the picture need not be readable. Quality 70
keeps a frame near 10 kB.
"""

from __future__ import annotations

import base64
import threading
from dataclasses import dataclass, field

import cv2
import numpy as np

from pmnav_bt.seams import Detection, Entity, Grounder, Observation, SurfaceMasks

FRAME_WIDTH = 320  # px, the JPEG's width
JPEG_QUALITY = 70
MAX_DETECTIONS = 24  # per frame: more would only crowd the picture


@dataclass
class TappedFrame:
    """A frame as the view shows it: ``jpeg`` (base64), its size, the clock ``stamp``,
    and what was found: ``found`` as JSON-ready dicts, ``what`` the calls made."""

    stamp: float
    jpeg: str
    width: int
    height: int
    scale: float  # JPEG pixels per frame pixel
    what: list[str] = field(default_factory=list)
    found: list[dict] = field(default_factory=list)

    def add(self, what: str, dets: list[Detection]) -> None:
        self.what.append(what)
        room = MAX_DETECTIONS - len(self.found)
        self.found += [_detection(d, what, self.scale) for d in dets[: max(0, room)]]

    def record(self) -> dict:
        """The tree log's ``view.frame`` entry."""
        return {
            "stamp": round(self.stamp, 3),
            "jpeg": self.jpeg,
            "size": [self.width, self.height],
            "what": list(self.what),
            "found": list(self.found),
        }


def _detection(d: Detection, what: str, scale: float) -> dict:
    return {
        "label": str(d.label)[:80],
        "box": [round(float(v) * scale, 1) for v in d.box],
        "score": round(float(d.score), 3),
        "entity": str(d.entity) if d.entity is not None else None,
        "kind": "sign" if what == "signs" else "target",
    }


def encode_frame(rgb: np.ndarray, stamp: float) -> TappedFrame:
    """``rgb`` (H, W, 3) shrunk to ``FRAME_WIDTH`` and encoded as a base64 JPEG."""
    h, w = rgb.shape[:2]
    scale = min(1.0, FRAME_WIDTH / max(1, w))
    size = (max(1, round(w * scale)), max(1, round(h * scale)))
    small = cv2.resize(rgb, size, interpolation=cv2.INTER_AREA) if scale < 1.0 else rgb
    ok, buf = cv2.imencode(
        ".jpg", cv2.cvtColor(small, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY]
    )
    jpeg = base64.b64encode(buf.tobytes()).decode("ascii") if ok else ""
    return TappedFrame(stamp, jpeg, size[0], size[1], scale)


class FrameTap:
    """A ``Grounder`` that keeps the last frame it grounded (see the module docstring); any
    other attribute is the wrapped grounder's."""

    def __init__(self, inner: Grounder) -> None:
        self.inner = inner
        self.needs_sim_labels = inner.needs_sim_labels
        self._lock = threading.Lock()
        self._frame: TappedFrame | None = None
        self._source: Observation | None = None
        self._new = False
        self._seen: list[str] = []  # rooms and landmarks named since the last take

    def detect(self, obs: Observation, target: Entity) -> list[Detection]:
        dets = self.inner.detect(obs, target)
        self._keep(obs, f"detect {target}", dets)
        return dets

    def read_signs(self, obs: Observation) -> list[Detection]:
        dets = self.inner.read_signs(obs)
        self._keep(obs, "signs", dets)
        return dets

    def surfaces(self, obs: Observation) -> SurfaceMasks:
        return self.inner.surfaces(obs)

    def __getattr__(self, name: str):
        """Whatever else the wrapped grounder offers (its optional capabilities, such as
        ``unread_plates`` for active reading or ``watch_reads``), as its own: a tapped
        grounder must do all that the untapped one does, or turning the view on would
        change what the robot does. Only called for names the tap does not have."""
        if name == "inner":  # not set yet (copying, unpickling): no recursion
            raise AttributeError(name)
        return getattr(self.inner, name)

    def _keep(self, obs: Observation, what: str, dets: list[Detection]) -> None:
        with self._lock:
            same = self._source is obs and self._frame is not None
        frame = self._frame if same else encode_frame(obs.rgb, obs.stamp)
        frame.add(what, list(dets))
        named = [str(d.entity) for d in dets if d.entity is not None]
        with self._lock:
            self._frame, self._source, self._new = frame, obs, True
            self._seen += [e for e in named if e not in self._seen]

    def take(self) -> tuple[TappedFrame | None, list[str]]:
        """The frame grounded since the last ``take`` (None: none new), and the rooms and
        landmarks named since (``str(Entity)``: "room room4", "landmark elevator1")."""
        with self._lock:
            frame = self._frame if self._new else None
            seen, self._seen, self._new = self._seen, [], False
        return frame, seen
