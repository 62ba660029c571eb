"""The ``gdino_sam`` grounder: GroundingDINO boxes, SAM masks, signs read by OCR (paper).

GroundingDINO grounds the target's class as a phrase ("door", "elevator", "stairs",
"reception desk"); it cannot tell one door from another, so the target's sign decides:
the sign is read and the door placed beside it as the ``ocr`` grounder does, and the
grounded box nearest that estimate (in the image) becomes the detection, with SAM's
mask for it. A target whose sign is not read is not detected (any door would do
otherwise). ``read_signs`` is the OCR reader's; ``surfaces`` come from depth geometry.

Weights load from local folders saved by transformers (``save_pretrained``): config.json,
model.safetensors, and for GroundingDINO its tokenizer and preprocessor_config.json.
Nothing is downloaded. Needs the ``gdino`` extra (transformers, Pillow) and torch.
"""

from __future__ import annotations

import threading
from pathlib import Path

import numpy as np

from pmnav_bt.backends import BackendDeps
from pmnav_bt.errors import BackendError, PmNavError
from pmnav_bt.loading import weights_file
from pmnav_bt.map.building import Building
from pmnav_bt.perception import depth as depth_geom
from pmnav_bt.perception.doors import DoorLayout
from pmnav_bt.perception.grounders.ocr import OcrGrounder, reader_and_layout
from pmnav_bt.perception.signs import SignReader
from pmnav_bt.perception.unread_plates import UnreadPlate
from pmnav_bt.seams import Detection, Entity, EntityKind, Observation, SurfaceMasks

# Phrases for landmark kinds GroundingDINO knows by another name.
KIND_PHRASES = {
    "elevator": "elevator door",
    "lift": "elevator door",
    "stairs": "stairs",
    "staircase": "stairs",
    "reception": "reception desk",
    "reception_desk": "reception desk",
    "desk": "desk",
}


def _model_dir(path: str, field: str, what: str) -> Path:
    p = Path(path).expanduser() if path else None
    if p is None or not (p / "config.json").is_file():
        raise BackendError(
            f"grounder.{field}: no {what} model at {path!r}; give a local folder saved with "
            f"transformers' save_pretrained (config.json, model.safetensors"
            f"{', tokenizer and preprocessor_config.json' if field == 'gdino_path' else ''})"
        )
    if not (p / "model.safetensors.index.json").is_file():  # sharded: transformers checks
        try:
            weights_file(p / "model.safetensors")
        except PmNavError as err:
            raise BackendError(f"grounder.{field}: {what} weights: {err}") from None
    return p


class GdinoSamGrounder:
    """Grounder with GroundingDINO + SAM (see the module docstring)."""

    needs_sim_labels = False

    def __init__(
        self,
        building: Building,
        gdino_path: str,
        sam_path: str,
        *,
        reader: SignReader | None = None,
        layout: DoorLayout | None = None,
        box_threshold: float = 0.35,
        text_threshold: float = 0.25,
    ):
        gdino_dir = _model_dir(gdino_path, "gdino_path", "GroundingDINO")
        sam_dir = _model_dir(sam_path, "sam_path", "SAM")
        try:
            import torch
            from transformers import (
                AutoTokenizer,
                GroundingDinoForObjectDetection,
                GroundingDinoImageProcessorPil,
                GroundingDinoProcessor,
                SamImageProcessorPil,
                SamModel,
            )
        except ImportError as e:  # pragma: no cover - depends on the install
            raise BackendError(
                "grounder.backend 'gdino_sam' needs transformers: pip install -e '.[gdino]'"
            ) from e
        self._torch = torch
        kw = {"local_files_only": True}
        self.gdino = GroundingDinoForObjectDetection.from_pretrained(gdino_dir, **kw).eval()
        self.processor = GroundingDinoProcessor(
            image_processor=GroundingDinoImageProcessorPil.from_pretrained(gdino_dir, **kw),
            tokenizer=AutoTokenizer.from_pretrained(gdino_dir, **kw),
        )
        self.sam = SamModel.from_pretrained(sam_dir, **kw).eval()
        self.sam_processor = SamImageProcessorPil.from_pretrained(sam_dir, **kw)
        self.box_threshold = box_threshold
        self.text_threshold = text_threshold
        self.building = building
        self.signs = OcrGrounder(building, reader, layout)
        self._lock = threading.Lock()  # one forward pass at a time

    # -- Grounder seam ------------------------------------------------------------------

    def read_signs(self, obs: Observation) -> list[Detection]:
        return self.signs.read_signs(obs)

    def watch_reads(self, observer) -> None:
        """The sign reader's frames (``perception.map_check.WatchesReads``)."""
        self.signs.watch_reads(observer)

    def unread_plates(self, since: float) -> list[UnreadPlate]:
        """The sign reader's (``perception.unread_plates.SeesUnreadPlates``)."""
        return self.signs.unread_plates(since)

    def plate_named(self, entity: Entity) -> UnreadPlate | None:
        """The sign reader's (``perception.unread_plates.SeesUnreadPlates``)."""
        return self.signs.plate_named(entity)

    def surfaces(self, obs: Observation) -> SurfaceMasks:
        return depth_geom.surfaces(obs)

    def detect(self, obs: Observation, target: Entity) -> list[Detection]:
        estimates = self.signs.detect(obs, target)
        if not estimates:
            return []
        grounded = self.ground(obs, self.phrase(target))
        out = []
        for est in estimates:
            best = _nearest(grounded, est)
            if best is None:
                out.append(est)
                continue
            out.append(
                Detection(
                    label=est.label,
                    box=best.box,
                    score=est.score * best.score,
                    mask=best.mask,
                    entity=target,
                    point=_mask_point(obs, best.mask) or est.point,
                )
            )
        return sorted(out, key=lambda d: -d.score)

    # -- models ---------------------------------------------------------------------------

    def phrase(self, target: Entity) -> str:
        """What GroundingDINO is asked to find for ``target``."""
        if target.kind == EntityKind.ROOM:
            return "door"
        kind = self.building.landmark(target.id).kind.lower()
        return KIND_PHRASES.get(kind, kind.replace("_", " "))

    def ground(self, obs: Observation, phrase: str) -> list[Detection]:
        """Every box GroundingDINO finds for ``phrase``, each with SAM's mask."""
        from PIL import Image

        torch = self._torch
        h, w = obs.rgb.shape[:2]
        image = Image.fromarray(obs.rgb)
        text = phrase.strip().lower().rstrip(".") + " ."
        with self._lock, torch.no_grad():
            inputs = self.processor(images=image, text=text, return_tensors="pt")
            outputs = self.gdino(**inputs)
            res = self.processor.post_process_grounded_object_detection(
                outputs,
                inputs["input_ids"],
                threshold=self.box_threshold,
                text_threshold=self.text_threshold,
                target_sizes=[(h, w)],
            )[0]
            boxes = res["boxes"].reshape(-1, 4).clamp(min=0)
            scores = res["scores"].reshape(-1)
            if len(boxes) == 0:
                return []
            masks = self._segment(image, boxes, (h, w))
        return [
            Detection(
                label=phrase,
                box=tuple(float(v) for v in b),  # type: ignore[arg-type]
                score=float(s),
                mask=m,
            )
            for b, s, m in zip(boxes.tolist(), scores.tolist(), masks, strict=True)
        ]

    def _segment(self, image, boxes, size: tuple[int, int]) -> list[np.ndarray]:
        inp = self.sam_processor(images=image, return_tensors="pt")
        rh, rw = (int(v) for v in inp["reshaped_input_sizes"][0])
        scale = self._torch.tensor([rw / size[1], rh / size[0], rw / size[1], rh / size[0]])
        out = self.sam(
            pixel_values=inp["pixel_values"],
            input_boxes=(boxes * scale)[None].float(),
            multimask_output=False,
        )
        masks = self.sam_processor.post_process_masks(
            out.pred_masks, inp["original_sizes"], inp["reshaped_input_sizes"]
        )[0]
        return [m[0].numpy().astype(bool) for m in masks]


def _nearest(grounded: list[Detection], est: Detection) -> Detection | None:
    """The grounded box whose centre is nearest ``est``'s, within ``est``'s box width."""
    cx, cy = est.centre
    reach = max(est.box[2] - est.box[0], 1.0)
    best, best_d = None, reach
    for g in grounded:
        gx, gy = g.centre
        d = float(np.hypot(gx - cx, gy - cy))
        if d <= best_d:
            best, best_d = g, d
    return best


def _mask_point(obs: Observation, mask: np.ndarray | None) -> tuple[float, float, float] | None:
    if obs.depth is None or mask is None or not mask.any():
        return None
    pts = depth_geom.back_project(obs)[mask]
    pts = pts[np.isfinite(pts).all(axis=1)]
    if len(pts) == 0:
        return None
    return tuple(float(v) for v in np.median(pts, axis=0))  # type: ignore[return-value]


def build(deps: BackendDeps) -> GdinoSamGrounder:
    """The ``gdino_sam`` back end from ``config.grounder`` (registry factory)."""
    g = deps.config.grounder
    reader, layout = reader_and_layout(g)
    return GdinoSamGrounder(
        deps.pm.building,
        g.gdino_path,
        g.sam_path,
        reader=reader,
        layout=layout,
        box_threshold=g.box_threshold,
        text_threshold=g.text_threshold,
    )
