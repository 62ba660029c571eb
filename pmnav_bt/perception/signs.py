"""Reading sign plates in RGB: cheap candidate regions, then PP-OCR on the crops.

Full-frame text detection (PP-OCRv4 through ``rapidocr-onnxruntime``) upscales every
frame to 736 px and costs about half a CPU-second. Signs are small, dense, high-contrast
text on a plain plate, so a morphological gradient finds them for a few milliseconds:
strong edges, closed horizontally into text lines, kept when the lines are dense, then
grouped into plates. Only those crops go through the text detector (upscaled so a text
line is about ``LINE_PX`` pixels high) and the recogniser. The models load once per
process and are shared by every reader. Text is filtered to printable ASCII (the
models also read Chinese).
"""

from __future__ import annotations

import functools
import math
import threading
from dataclasses import dataclass, replace

import cv2
import numpy as np

from pmnav_bt.errors import BackendError
from pmnav_bt.seams import ImageReading, ReadingView

Box = tuple[float, float, float, float]  # x0, y0, x1, y1 (pixels)

LINE_PX = 32.0  # text-line height the detector sees after upscaling a crop
MIN_LINE_PX = 5  # lines lower than this in the frame cannot be read: not candidates
PAD_LINES = 0.8  # crop padding around a plate candidate, in line heights
INK_CONTRAST = 40  # text differs from its plate by at least this much (largest RGB channel)
LINE_PER_CAP = 1.3  # a text line's height over a character's


@dataclass(frozen=True)
class TextLine:
    """One line of text read in a frame: ASCII text, recogniser score, box in frame pixels,
    and the recogniser's confidence in each character of ``text`` (its CTC step's
    probability; empty where unknown). ``score`` is their mean over the raw line."""

    text: str
    score: float
    box: Box
    char_scores: tuple[float, ...] = ()


@dataclass(frozen=True)
class SignText:
    """The text lines read inside one sign candidate (top to bottom), and the plate's box."""

    lines: tuple[TextLine, ...]
    box: Box

    @property
    def text(self) -> str:
        return " ".join(line.text for line in self.lines)

    @property
    def score(self) -> float:
        return float(min(line.score for line in self.lines)) if self.lines else 0.0


_ENGINE_LOCK = threading.Lock()


@functools.lru_cache(maxsize=4)
def _engine(threads: int):
    """The rapidocr engine (models loaded once per process and thread count)."""
    try:
        from rapidocr_onnxruntime import RapidOCR
    except ImportError as e:  # pragma: no cover - depends on the install
        raise BackendError(
            "grounder.backend 'ocr' needs rapidocr-onnxruntime: "
            "pip install -e '.[ocr]' && pip install --no-deps rapidocr-onnxruntime==1.4.4 "
            "(or `make setup`)"
        ) from e
    return RapidOCR(intra_op_num_threads=threads, inter_op_num_threads=1, print_verbose=False)


def text_line_boxes(gray: np.ndarray, min_h: int = MIN_LINE_PX) -> list[tuple[Box, float]]:
    """Dense, high-contrast regions: text lines, or whole plates where the text touches the
    plate's border; each with its estimated text-line height (pixels).

    The closing joins the characters of small text; the characters of text seen close up
    (gaps wider than the closing) are joined afterwards by ``join_characters``."""
    h, w = gray.shape
    grad = cv2.morphologyEx(gray, cv2.MORPH_GRADIENT, np.ones((3, 3), np.uint8))
    edges = (grad >= 60).astype(np.uint8)
    k = max(3, w // 80)
    kernel = cv2.getStructuringElement(cv2.MORPH_RECT, (k, max(1, k // 3)))
    closed = cv2.morphologyEx(edges, cv2.MORPH_CLOSE, kernel)
    n, _, stats, _ = cv2.connectedComponentsWithStats(closed, connectivity=8)
    boxes = [
        (int(x), int(y), int(x + bw), int(y + bh))
        for x, y, bw, bh, _ in stats[1:]
        if min_h <= bh <= h // 4
    ]
    out: list[tuple[Box, float]] = []
    for (x0, y0, x1, y1), chars in join_characters(boxes):
        bw, bh = x1 - x0, y1 - y0
        if bw < min_h or bw > w * 0.9:
            continue
        fill = float(edges[y0:y1, x0:x1].mean())
        if fill >= 0.25 and bw >= 0.7 * bh:
            # sparse and not a row of characters: a plate, about 3 lines high
            line_h = bh if fill >= 0.45 or chars > 1 else bh / 3.0
            out.append(((float(x0), float(y0), float(x1), float(y1)), float(line_h)))
    return out


def join_characters(
    boxes: list[tuple[int, int, int, int]],
) -> list[tuple[tuple[int, int, int, int], int]]:
    """Join character-shaped boxes (no wider than 1.2 x their height) standing side by side
    on one line (similar heights, overlapping rows, gaps under 0.6 x the height) into
    words: (box, number of characters). Other boxes pass through with a count of 1."""

    def char_like(b):
        return b[2] - b[0] <= 1.2 * (b[3] - b[1])

    out: list[list] = []
    for b in sorted(boxes):
        bh = b[3] - b[1]
        for g in out:
            gb, last = g[0], g[2]
            lh = last[3] - last[1]
            rows = min(b[3], last[3]) - max(b[1], last[1])
            if (
                g[1] > 0
                and char_like(b)
                and char_like(last)
                and max(bh, lh) <= 1.5 * min(bh, lh)
                and rows >= 0.6 * min(bh, lh)
                and -0.2 * lh <= b[0] - last[2] <= 0.6 * max(bh, lh)
            ):
                g[0] = (min(gb[0], b[0]), min(gb[1], b[1]), max(gb[2], b[2]), max(gb[3], b[3]))
                g[1] += 1
                g[2] = b
                break
        else:
            out.append([b, 1 if char_like(b) else 0, b])
    return [(g[0], max(1, g[1])) for g in out]


def ink_line_height(crop: np.ndarray, box: Box) -> float | None:
    """The text-line height (pixels) the characters inside ``box`` of ``crop`` measure,
    whatever their colour and the plate's: None where none stand apart.

    The candidate finder's line height is a guess where text and plate close into one
    blob (a coloured plate's border is as strong an edge as its text): the blob is taken
    for one line, and a plate of three lines is shrunk three times too small to read.
    Here the plate's own colour is the median of the box; ink is what differs from it
    (Otsu's threshold on the largest channel difference, either polarity); characters
    are ink components that do not touch the box's edge (the plate's border and its
    backing do) and are taller than wide at most 4 times (not rules or frames). A text
    line is about 1.3 times their median height: the capitals' for numbers, nearer the
    lower case's for names (an estimate too small costs only a larger upscale; one too
    large makes the text unreadable)."""
    x0, y0 = max(0, int(box[0])), max(0, int(box[1]))
    x1, y1 = min(crop.shape[1], int(math.ceil(box[2]))), min(crop.shape[0], int(math.ceil(box[3])))
    region = crop[y0:y1, x0:x1].astype(np.int16)
    if region.shape[0] < 6 or region.shape[1] < 6:
        return None
    bg = np.median(region.reshape(-1, 3), axis=0)
    diff = np.abs(region - bg).max(axis=2).astype(np.uint8)
    if int(diff.max()) < INK_CONTRAST:
        return None
    _, ink = cv2.threshold(diff, 0, 1, cv2.THRESH_BINARY + cv2.THRESH_OTSU)
    n, _, stats, _ = cv2.connectedComponentsWithStats(ink, connectivity=8)
    rh, rw = ink.shape
    heights = [
        int(bh)
        for x, y, bw, bh, _ in stats[1:]
        if x > 0 and y > 0 and x + bw < rw and y + bh < rh
        and 2 <= bh <= 0.8 * rh and bw <= 4 * bh and bh <= 4 * bw
    ]
    if not heights:
        return None
    return float(LINE_PER_CAP * np.median(heights))


def group_lines(lines: list[tuple[Box, float]]) -> list[tuple[Box, float]]:
    """Group regions stacked close together into plates: (plate box, text-line height)."""
    groups: list[list[tuple[Box, float]]] = []
    for b, lh in sorted(lines, key=lambda r: r[0][1]):
        for g in groups:
            gx0, gx1 = min(q[0] for q, _ in g), max(q[2] for q, _ in g)
            gy1 = max(q[3] for q, _ in g)
            gap = b[1] - gy1
            overlap = min(b[2], gx1) - max(b[0], gx0)
            if gap <= 1.5 * max(lh, g[-1][1]) and overlap > -lh:
                g.append((b, lh))
                break
        else:
            groups.append([(b, lh)])
    out = []
    for g in groups:
        qs = [q for q, _ in g]
        box = (
            min(q[0] for q in qs),
            min(q[1] for q in qs),
            max(q[2] for q in qs),
            max(q[3] for q in qs),
        )
        out.append((box, float(min(lh for _, lh in g))))
    return out


def _ascii(text: str, scores: list[float]) -> tuple[str, tuple[float, ...]]:
    """``text`` filtered to printable ASCII and stripped, with the scores of the kept
    characters."""
    kept = [(c, float(s)) for c, s in zip(text, scores, strict=True) if 32 <= ord(c) < 127]
    while kept and kept[0][0] == " ":
        kept.pop(0)
    while kept and kept[-1][0] == " ":
        kept.pop()
    return "".join(c for c, _ in kept), tuple(s for _, s in kept)


def _quad_crop(img: np.ndarray, quad: np.ndarray) -> np.ndarray:
    """The text line inside ``quad`` (4x2, clockwise from top-left), warped upright."""
    q = quad.astype(np.float32)
    w = int(max(np.linalg.norm(q[0] - q[1]), np.linalg.norm(q[2] - q[3])))
    h = int(max(np.linalg.norm(q[0] - q[3]), np.linalg.norm(q[1] - q[2])))
    w, h = max(w, 1), max(h, 1)
    dst = np.float32([[0, 0], [w, 0], [w, h], [0, h]])
    m = cv2.getPerspectiveTransform(q, dst)
    return cv2.warpPerspective(
        img, m, (w, h), flags=cv2.INTER_CUBIC, borderMode=cv2.BORDER_REPLICATE
    )


def scale_box(b: Box, f: float) -> Box:
    """Box ``b`` scaled by ``f`` (from one image size to another)."""
    return (b[0] * f, b[1] * f, b[2] * f, b[3] * f)


def scale_sign(sign: SignText, f: float) -> SignText:
    """``sign`` with its boxes scaled by ``f`` (from one image size to another)."""
    lines = tuple(replace(ln, box=scale_box(ln.box, f)) for ln in sign.lines)
    return SignText(lines, scale_box(sign.box, f))


class SignReader:
    """Reads the sign plates of an RGB frame (see the module docstring).

    ``threads``: onnxruntime threads per model; ``max_candidates``: plates read per frame
    (the largest first); ``min_score``: recogniser score below which a line is dropped.
    """

    def __init__(self, threads: int = 1, max_candidates: int = 4, min_score: float = 0.6):
        self.threads = threads
        self.max_candidates = max_candidates
        self.min_score = min_score
        self._ocr = _engine(threads)

    def candidates(
        self, rgb: np.ndarray, min_line_px: float = MIN_LINE_PX
    ) -> list[tuple[Box, float]]:
        """Plate candidates: (box in frame pixels, text-line height), largest first; lines
        lower than ``min_line_px`` (pixels of this frame) are left out.

        Frames wider than 320 px are searched at 320 px (the cue needs no detail).
        """
        h, w = rgb.shape[:2]
        s = min(1.0, 320.0 / w)
        small = rgb if s == 1.0 else cv2.resize(rgb, (int(w * s), int(h * s)), cv2.INTER_AREA)
        gray = cv2.cvtColor(small, cv2.COLOR_RGB2GRAY)
        min_h = max(2, int(round(min_line_px * s)))
        plates = group_lines(text_line_boxes(gray, min_h))
        plates = [((b[0] / s, b[1] / s, b[2] / s, b[3] / s), lh / s) for b, lh in plates]
        plates.sort(key=lambda p: -(p[0][2] - p[0][0]) * (p[0][3] - p[0][1]))
        return plates[: self.max_candidates]

    def read(
        self, rgb: np.ndarray | ReadingView, candidates: list[tuple[Box, float]] | None = None
    ) -> list[SignText]:
        """Every candidate plate whose text could be read, with its lines.

        ``rgb``: the frame, or a ``ReadingView`` whose candidate crops are made one by
        one (then ``candidates`` are needed). ``candidates``: (box, text-line height) in
        ``rgb``'s pixels, if found elsewhere (default: ``self.candidates(rgb)``). Lines
        are found per candidate, then recognised together in one batch.
        """
        if candidates is None:
            candidates = self.candidates(rgb)
        found = [(box, self.find_lines(rgb, box, lh)) for box, lh in candidates]
        crops = [crop for _, lines in found for _, crop in lines]
        if not crops:
            return []
        # word boxes: the per-character confidences come with them
        results, _ = self._ocr.text_rec(crops, return_word_box=True)
        out, i = [], 0
        for box, lines in found:
            read = []
            for line_box, _ in lines:
                raw, score, info = results[i]
                i += 1
                text, chars = _ascii(raw, info[4] if raw else [])
                if text and score >= self.min_score:
                    read.append(TextLine(text, float(score), line_box, chars))
            if read:
                out.append(SignText(tuple(read), box))
        return out

    def find_lines(
        self, rgb: np.ndarray | ReadingView, box: Box, line_h: float
    ) -> list[tuple[Box, np.ndarray]]:
        """Text lines inside ``box`` (padded), top to bottom: (box in frame pixels, upright
        BGR crop for the recogniser). Lines too low to be read are left out."""
        src = ImageReading(rgb) if isinstance(rgb, np.ndarray) else rgb
        pad = PAD_LINES * line_h
        x0, y0 = int(max(0, box[0] - pad)), int(max(0, box[1] - pad))
        x1 = int(min(src.width, box[2] + pad + 1))
        y1 = int(min(src.height, box[3] + pad + 1))
        crop = src.crop((x0, y0, x1, y1))
        if crop.size == 0:
            return []
        inked = ink_line_height(crop, (box[0] - x0, box[1] - y0, box[2] - x0, box[3] - y0))
        if inked is not None and inked < line_h:
            # smaller text than guessed: less padding too (the crop is upscaled the more)
            line_h, pad = inked, PAD_LINES * inked
            cx0, cy0 = int(max(x0, box[0] - pad)), int(max(y0, box[1] - pad))
            cx1, cy1 = int(min(x1, box[2] + pad + 1)), int(min(y1, box[3] + pad + 1))
            crop = crop[cy0 - y0 : cy1 - y0, cx0 - x0 : cx1 - x0]
            x0, y0 = cx0, cy0
        scale = float(np.clip(LINE_PX / max(line_h, 1.0), 0.5, 6.0))
        big = cv2.resize(crop, None, fx=scale, fy=scale, interpolation=cv2.INTER_CUBIC)
        bgr = np.ascontiguousarray(big[:, :, ::-1])
        det = self._ocr.text_det
        with _ENGINE_LOCK:  # the detector's limits are per-call state
            det.limit_type, det.limit_side_len = "max", max(bgr.shape[:2])
            quads, _ = det(bgr)
        if quads is None or len(quads) == 0:
            return []
        quads = sorted(quads, key=lambda q: (float(q[:, 1].mean()), float(q[:, 0].min())))
        out = []
        for q in quads:
            qb = (
                x0 + float(q[:, 0].min()) / scale,
                y0 + float(q[:, 1].min()) / scale,
                x0 + float(q[:, 0].max()) / scale,
                y0 + float(q[:, 1].max()) / scale,
            )
            if qb[3] - qb[1] >= 0.8 * MIN_LINE_PX:
                out.append((qb, _quad_crop(bgr, q)))
        return out
