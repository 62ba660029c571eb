"""Train the pictogram reader (``perception/pictograms.py``) and calibrate its threshold.

Data: rendered candidate crops of development worlds (``pictogram_data --split dev``),
plus plates drawn by the simulator's plate renderer and seen as a camera would
(``pictogram_data.synthetic``: many more styles than rendered worlds give). A fifth of
the rendered worlds (by world, never by view) is kept back for calibration. Training
augments each patch the way views differ: shifted and scaled by up to a tenth (the
finder's box is loose), mirrored for text and background only (a mirrored toilet plate
is not a toilet plate of the simulator's), and with its grey levels inverted (light on
dark as dark on light). Torch on the CPU, a few minutes.

**Calibration.** ``sighting_p`` is the smallest probability above every non-toilet
patch of the calibration worlds' p(toilet), and at least ``MIN_SIGHTING_P``: on the
calibration worlds the reader then makes no false sighting. It is written beside the
weights with the counts it was chosen on.

``--eval FILE.npz`` measures a model on other renders (the held-out split): per class
accuracy and precision, toilet sightings' recall and precision at the threshold, false
sightings, and CPU time per plate.

Run:
  python -m pmnav_bt.experiments.pictogram_data --split dev --worlds 30 --views 20 --out dev.npz
  python -m pmnav_bt.experiments.pictogram_data --split dev --synthetic 5000 --out syn.npz
  python -m pmnav_bt.experiments.pictogram_train --data dev.npz --synthetic syn.npz \
      --out pmnav_bt/data/pictograms.safetensors
  python -m pmnav_bt.experiments.pictogram_data --split heldout --worlds 16 --views 25 \
      --out heldout.npz
  python -m pmnav_bt.experiments.pictogram_train --calibrate more_dev.npz
  python -m pmnav_bt.experiments.pictogram_train --eval heldout.npz
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from pmnav_bt.loading import atomic_write_text
from pmnav_bt.perception.pictograms import (
    CLASSES,
    CONV_CHANNELS,
    HIDDEN,
    INPUT_H,
    INPUT_W,
    WEIGHTS,
    PictogramReader,
    forward,
    normalise,
    softmax,
)

MIN_SIGHTING_P = 0.9
TOILET = CLASSES.index("toilet")


def network():
    """The reader's layers in torch (the same names and shapes as ``pictograms.forward``)."""
    import torch.nn as nn

    layers: dict[str, nn.Module] = {}
    c = 1
    for k, o in enumerate(CONV_CHANNELS):
        layers[f"conv{k}"] = nn.Conv2d(c, o, 3, padding=1)
        c = o
    flat = c * (INPUT_H // 2 ** len(CONV_CHANNELS)) * (INPUT_W // 2 ** len(CONV_CHANNELS))
    layers["fc0"] = nn.Linear(flat, HIDDEN)
    layers["fc1"] = nn.Linear(HIDDEN, len(CLASSES))

    class Net(nn.Module):
        def __init__(self):
            super().__init__()
            for name, layer in layers.items():
                self.add_module(name, layer)

        def forward(self, x):
            import torch.nn.functional as F

            for k in range(len(CONV_CHANNELS)):
                x = F.max_pool2d(F.relu(getattr(self, f"conv{k}")(x)), 2)
            x = F.relu(self.fc0(x.flatten(1)))
            return self.fc1(x)

    return Net()


def augment(x: np.ndarray, y: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Normalised patches (N, 1, H, W) shifted and scaled a little, mirrored (not toilet
    plates) and inverted at random."""
    import cv2

    out = np.empty_like(x)
    for i in range(len(x)):
        s = float(rng.uniform(0.9, 1.1))
        tx, ty = rng.uniform(-0.08, 0.08) * INPUT_W, rng.uniform(-0.1, 0.1) * INPUT_H
        m = np.float32([[s, 0, (1 - s) * INPUT_W / 2 + tx], [0, s, (1 - s) * INPUT_H / 2 + ty]])
        img = cv2.warpAffine(x[i, 0], m, (INPUT_W, INPUT_H), borderMode=cv2.BORDER_REPLICATE)
        if y[i] != TOILET and rng.random() < 0.5:
            img = img[:, ::-1]
        if rng.random() < 0.5:
            img = -img
        out[i, 0] = img
    return out


def split_worlds(meta: np.ndarray, frac: float, seed: int) -> np.ndarray:
    """A mask of the patches whose world (building, world seed) is kept for calibration."""
    worlds = sorted({(m[0], int(m[1])) for m in meta})
    rng = np.random.default_rng(seed)
    held = {worlds[i] for i in rng.permutation(len(worlds))[: max(1, int(frac * len(worlds)))]}
    return np.array([(m[0], int(m[1])) in held for m in meta])


def train(
    patches: np.ndarray, labels: np.ndarray, epochs: int, seed: int
) -> dict[str, np.ndarray]:
    import torch

    torch.manual_seed(seed)
    torch.set_num_threads(2)
    rng = np.random.default_rng(seed)
    x, y = normalise(patches), labels
    net = network()
    opt = torch.optim.Adam(net.parameters(), lr=2e-3, weight_decay=1e-4)
    counts = np.bincount(y, minlength=len(CLASSES)).astype(np.float32)
    weight = torch.tensor(counts.sum() / (len(CLASSES) * np.maximum(counts, 1)))
    loss_fn = torch.nn.CrossEntropyLoss(weight=weight)
    for epoch in range(epochs):
        order = rng.permutation(len(x))
        total = 0.0
        for b in range(0, len(order), 128):
            idx = order[b : b + 128]
            xb = torch.from_numpy(augment(x[idx], y[idx], rng))
            loss = loss_fn(net(xb), torch.from_numpy(y[idx]))
            opt.zero_grad()
            loss.backward()
            opt.step()
            total += loss.item() * len(idx)
        print(f"epoch {epoch + 1}/{epochs}: loss {total / len(x):.4f}", flush=True)
    return {k: v.detach().numpy().astype(np.float32) for k, v in net.state_dict().items()}


def calibrate(p_toilet: np.ndarray, labels: np.ndarray) -> float:
    """The sighting threshold (module docstring) from calibration patches."""
    neg = p_toilet[labels != TOILET]
    top = float(neg.max()) if len(neg) else 0.0
    return float(max(MIN_SIGHTING_P, min(0.999, np.ceil((top + 1e-4) * 1000) / 1000)))


def probabilities(params: dict[str, np.ndarray], patches: np.ndarray) -> np.ndarray:
    return softmax(forward(params, normalise(patches)))


def report(
    params: dict[str, np.ndarray], threshold: float, patches: np.ndarray, labels: np.ndarray,
    what: str,
) -> None:
    """Per class accuracy and precision, sightings at the threshold, CPU ms per plate."""
    c0 = time.process_time()
    probs = probabilities(params, patches)
    cpu_ms = 1000 * (time.process_time() - c0) / max(len(patches), 1)
    pred = probs.argmax(axis=1)
    print(f"{what}: {len(labels)} patches")
    for k, name in enumerate(CLASSES):
        n, called = int((labels == k).sum()), int((pred == k).sum())
        acc = 100 * (pred[labels == k] == k).mean() if n else float("nan")
        prec = 100 * (labels[pred == k] == k).mean() if called else float("nan")
        print(f"  {name:>10s}: n {n:5d}  accuracy (recall) {acc:5.1f}%  precision {prec:5.1f}%")
    sight = probs[:, TOILET] >= threshold
    tp = int((sight & (labels == TOILET)).sum())
    fp = int((sight & (labels != TOILET)).sum())
    n_t = int((labels == TOILET).sum())
    print(
        f"  toilet sightings at p >= {threshold:.3f}: {tp} of {n_t} toilet patches "
        f"({100 * tp / max(n_t, 1):.1f}%), false sightings {fp} of {len(labels) - n_t}"
    )
    print(f"  CPU {cpu_ms:.3f} ms per plate (batch of {len(labels)}, numpy)")


def recalibrate(out: Path, data: str) -> None:
    """Set the model's ``sighting_p`` from the patches of ``data``: development worlds
    neither its training nor its first calibration saw (more of them than the fifth kept
    back, where training data were few)."""
    d = np.load(data, allow_pickle=True)
    r = PictogramReader(out)
    p_toilet = r.probabilities(d["patches"])[:, TOILET]
    threshold = calibrate(p_toilet, d["labels"])
    meta = dict(r.meta)
    worlds = sorted({f"{m[0]}@{int(m[1])}" for m in d["meta"]})
    meta["sighting_p"] = threshold
    meta["recalibration"] = {
        "worlds": worlds,
        "patches": {c: int((d["labels"] == k).sum()) for k, c in enumerate(CLASSES)},
        "highest non-toilet p": round(float(p_toilet[d["labels"] != TOILET].max()), 4),
    }
    atomic_write_text(out.with_suffix(".json"), json.dumps(meta, indent=1) + "\n")
    print(f"sighting_p {threshold:.3f} (was {r.sighting_p:.3f}); wrote {out.with_suffix('.json')}")
    report(r.params, threshold, d["patches"], d["labels"], f"calibration ({data})")


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--data", help="rendered development patches (.npz of pictogram_data)")
    ap.add_argument("--synthetic", help="synthetic patches to add (.npz of pictogram_data "
                    "--synthetic N)")
    ap.add_argument("--epochs", type=int, default=12)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default=str(WEIGHTS), help=".safetensors to write (.json beside)")
    ap.add_argument("--eval", help="measure the model at --out on this .npz instead")
    ap.add_argument("--calibrate", help="calibrate the model at --out again on this .npz "
                    "(development worlds it was not trained on) instead")
    args = ap.parse_args(argv)
    if args.calibrate:
        recalibrate(Path(args.out), args.calibrate)
        return
    if args.eval:
        d = np.load(args.eval, allow_pickle=True)
        r = PictogramReader(args.out)
        report(r.params, r.sighting_p, d["patches"], d["labels"], f"held out ({args.eval})")
        return
    if not args.data:
        ap.error("--data is needed to train (or --eval to measure)")
    from safetensors.numpy import save_file

    d = np.load(args.data, allow_pickle=True)
    calib = split_worlds(d["meta"], 0.2, args.seed)
    tp, tl = d["patches"][~calib], d["labels"][~calib]
    n_syn = 0
    if args.synthetic:
        s = np.load(args.synthetic, allow_pickle=True)
        tp, tl = np.concatenate([tp, s["patches"]]), np.concatenate([tl, s["labels"]])
        n_syn = len(s["labels"])
    t0 = time.time()
    params = train(tp, tl, args.epochs, args.seed)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    save_file(params, str(out))
    cp, cl = d["patches"][calib], d["labels"][calib]
    threshold = calibrate(probabilities(params, cp)[:, TOILET], cl)
    meta = {
        "classes": list(CLASSES),
        "sighting_p": threshold,
        "calibration": {
            "rule": "smallest p above every non-toilet calibration patch, at least "
            f"{MIN_SIGHTING_P}",
            "worlds": int(len({(m[0], int(m[1])) for m in d["meta"][calib]})),
            "patches": {c: int((cl == k).sum()) for k, c in enumerate(CLASSES)},
        },
        "training": {
            "rendered": {c: int((d["labels"][~calib] == k).sum()) for k, c in enumerate(CLASSES)},
            "synthetic": n_syn,
            "epochs": args.epochs,
            "seed": args.seed,
            "command": "python -m pmnav_bt.experiments.pictogram_train (docs/perception.md)",
        },
    }
    atomic_write_text(out.with_suffix(".json"), json.dumps(meta, indent=1) + "\n")
    print(f"trained in {time.time() - t0:.0f} s; sighting_p {threshold:.3f}; wrote {out}")
    report(params, threshold, cp, cl, "calibration worlds (development)")


if __name__ == "__main__":
    main()
