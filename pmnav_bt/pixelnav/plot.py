"""Training curves as a PNG, drawn with OpenCV (already a dependency)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import cv2
import numpy as np

W, H = 560, 300
PAD_L, PAD_R, PAD_T, PAD_B = 58, 14, 48, 40
COLOURS = [(200, 90, 30), (40, 40, 220), (40, 160, 40), (150, 60, 150)]  # BGR


def _panel(
    series: dict[str, tuple[Sequence[float], Sequence[float]]], title: str, ylabel: str
) -> np.ndarray:
    img = np.full((H, W, 3), 255, np.uint8)
    pts = [(np.asarray(x, float), np.asarray(y, float)) for x, y in series.values() if len(x)]
    if not pts:
        return img
    xs = np.concatenate([p[0] for p in pts])
    ys = np.concatenate([p[1] for p in pts])
    x0, x1 = float(xs.min()), float(max(xs.max(), xs.min() + 1))
    y0, y1 = float(ys.min()), float(ys.max())
    if y1 - y0 < 1e-9:
        y1 = y0 + 1.0
    y0, y1 = y0 - 0.05 * (y1 - y0), y1 + 0.05 * (y1 - y0)

    def px(x, y):
        u = PAD_L + (x - x0) / (x1 - x0) * (W - PAD_L - PAD_R)
        v = H - PAD_B - (y - y0) / (y1 - y0) * (H - PAD_T - PAD_B)
        return np.stack([u, v], -1).round().astype(np.int32)

    cv2.rectangle(img, (PAD_L, PAD_T), (W - PAD_R, H - PAD_B), (0, 0, 0), 1)
    font = cv2.FONT_HERSHEY_SIMPLEX
    for f in np.linspace(0, 1, 5):
        y = y0 + f * (y1 - y0)
        v = int(px(np.array(x0), np.array(y))[1])
        cv2.line(img, (PAD_L - 4, v), (PAD_L, v), (0, 0, 0), 1)
        cv2.putText(img, f"{y:.3g}", (2, v + 4), font, 0.38, (0, 0, 0), 1, cv2.LINE_AA)
        x = x0 + f * (x1 - x0)
        u = int(px(np.array(x), np.array(y0))[0])
        cv2.line(img, (u, H - PAD_B), (u, H - PAD_B + 4), (0, 0, 0), 1)
        cv2.putText(
            img, f"{x:.0f}", (u - 12, H - PAD_B + 16), font, 0.38, (0, 0, 0), 1, cv2.LINE_AA
        )
    cv2.putText(img, title, (PAD_L, 20), font, 0.5, (0, 0, 0), 1, cv2.LINE_AA)
    cv2.putText(img, ylabel, (2, PAD_T - 10), font, 0.38, (0, 0, 0), 1, cv2.LINE_AA)
    cv2.putText(img, "step", (W - 50, H - 8), font, 0.4, (0, 0, 0), 1, cv2.LINE_AA)
    for i, (name, (x, y)) in enumerate(series.items()):
        if not len(x):
            continue
        c = COLOURS[i % len(COLOURS)]
        cv2.polylines(
            img, [px(np.asarray(x, float), np.asarray(y, float))], False, c, 2, cv2.LINE_AA
        )
        cv2.putText(img, name, (PAD_L + 165 * i, PAD_T - 10), font, 0.42, c, 1, cv2.LINE_AA)
    return img


def save_curves(history: list[dict], path: str | Path) -> Path:
    """Loss and accuracy curves from the training history (one dict per evaluation)."""
    steps = [h["step"] for h in history]

    def col(key):
        return [h[key] for h in history]

    top = _panel(
        {"train loss": (steps, col("train_loss")), "val loss": (steps, col("val_loss"))},
        "PixelNav imitation loss (action CE + distance + tracking)",
        "loss",
    )
    bottom = _panel(
        {
            "val action acc": (steps, col("val_acc")),
            "val stop recall": (steps, col("val_stop_recall")),
            "train action acc": (steps, col("train_acc")),
        },
        "action accuracy; validation: buildings never trained on",
        "fraction",
    )
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    cv2.imwrite(str(path), np.vstack([top, bottom]))
    return path
