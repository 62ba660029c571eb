"""Imitation training of the PixelNav network on ``gen``'s shards.

A sample is one window of up to ``history`` frames of an expert episode with its goal
frame; every frame of the window is supervised (the transformer is causal). The goal
frame is the episode's first frame, or (``reseat``) a later frame with the goal pixel
where the expert saw it then, as after a re-grounding. Frames are flipped left-right
(turns swapped), jittered in brightness and sometimes slightly blurred. Loss:
cross-entropy on the action, squared error on the temporal distance, smooth L1 on the
goal track (where the goal is ahead).

Seeded and resumable: batch ``i`` is drawn from ``rng([seed, i])``, so a resumed run
draws the same batches as one that never stopped. Validation uses the shards of the last
buildings (``val_fraction``), never seen in training. Checkpoints are safetensors (the
model, and the optimizer's tensors) with a JSON state beside them.
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path

import cv2
import numpy as np
import torch
from pydantic import BaseModel, ConfigDict, Field
from safetensors.torch import load_file, save_file
from torch.nn import functional as F

from pmnav_bt.errors import PmNavError
from pmnav_bt.pixelnav.dataset import LEFT, RIGHT, STOP, load_shards
from pmnav_bt.pixelnav.model import PRESETS, TDIST_SCALE, ModelConfig, PixelNavNet

MODEL_FILE = "model.safetensors"
OPTIM_FILE = "optim.safetensors"
STATE_FILE = "state.json"
CURVES_FILE = "curves.png"


class TrainError(PmNavError):
    """A training folder or data folder that cannot be used as asked."""


class TrainConfig(BaseModel):
    """What ``pmnav pixelnav train`` does."""

    model_config = ConfigDict(extra="forbid")

    model: ModelConfig = Field(default_factory=ModelConfig)
    seed: int = Field(0, ge=0)
    steps: int = Field(6000, ge=1)
    batch: int = Field(32, ge=1)
    lr: float = Field(1e-3, gt=0.0)
    weight_decay: float = Field(0.01, ge=0.0)
    warmup: int = Field(200, ge=0)
    val_fraction: float = Field(0.1, gt=0.0, lt=1.0, description="shards held out (last)")
    val_batches: int = Field(8, ge=1)
    eval_every: int = Field(250, ge=1)
    reseat: float = Field(0.3, ge=0.0, le=1.0, description="goal frame from a later step")
    flip: float = Field(0.5, ge=0.0, le=1.0)
    blur: float = Field(0.3, ge=0.0, le=1.0, description="chance of a slight blur")
    stop_weight: float = Field(2.0, gt=0.0, description="cross-entropy weight of STOP")
    tdist_weight: float = Field(0.5, ge=0.0)
    track_weight: float = Field(1.0, ge=0.0)
    threads: int = Field(1, ge=1, description="CPU threads for torch")
    init: str = Field("", description="start from these weights (.safetensors): fine-tuning")


def pick_device() -> torch.device:
    """CUDA when present, else the CPU (never required)."""
    return torch.device("cuda" if torch.cuda.is_available() else "cpu")


class Sampler:
    """Windows of episodes -> batches of arrays (numpy, uint8 frames)."""

    def __init__(self, data: dict[str, np.ndarray], episodes: np.ndarray, cfg: TrainConfig):
        self.d, self.eps, self.cfg = data, episodes, cfg
        self.w, self.h, self.t = cfg.model.width, cfg.model.height, cfg.model.history
        if data["frames"].shape[1:3] != (self.h, self.w):
            raise TrainError(
                f"data frames are {data['frames'].shape[2]}x{data['frames'].shape[1]} px, "
                f"the model wants {self.w}x{self.h} (model.width/height)"
            )

    def batch(self, rng: np.random.Generator, size: int) -> dict[str, np.ndarray]:
        d, t, w, h = self.d, self.t, self.w, self.h
        out = {
            "goal_frame": np.zeros((size, h, w, 3), np.uint8),
            "goal_px": np.zeros((size, 2), np.float32),
            "frames": np.zeros((size, t, h, w, 3), np.uint8),
            "pad": np.ones((size, t), bool),
            "action": np.zeros((size, t), np.int64),
            "tdist": np.zeros((size, t), np.float32),
            "track": np.zeros((size, t, 2), np.float32),
            "track_valid": np.zeros((size, t), bool),
        }
        for b in range(size):
            e = int(self.eps[rng.integers(len(self.eps))])
            o0, o1 = int(d["offsets"][e]), int(d["offsets"][e + 1])
            n = o1 - o0
            k, gpx = 0, d["goal_px"][e]
            if rng.random() < self.cfg.reseat and n > 1:
                tr, ok = d["track"][o0 + 1 : o1], d["track_valid"][o0 + 1 : o1]
                inside = ok & (tr[:, 0] >= 0) & (tr[:, 0] < 1) & (tr[:, 1] >= 0) & (tr[:, 1] < 1)
                idx = np.nonzero(inside)[0]
                if len(idx):
                    k = int(idx[rng.integers(len(idx))]) + 1
                    gpx = d["track"][o0 + k] * (w, h)
            end = int(rng.integers(k + 1, n + 1))
            start = max(k, end - t)
            m = end - start
            sl = slice(o0 + start, o0 + end)
            out["goal_frame"][b] = d["frames"][o0 + k]
            out["goal_px"][b] = gpx
            out["frames"][b, :m] = d["frames"][sl]
            out["pad"][b, :m] = False
            out["action"][b, :m] = d["actions"][sl]
            out["tdist"][b, :m] = d["tdist"][sl] / TDIST_SCALE
            out["track"][b, :m] = d["track"][sl]
            out["track_valid"][b, :m] = d["track_valid"][sl]
            if rng.random() < self.cfg.flip:
                flip(out, b, w)
            gain = rng.uniform(0.8, 1.2)
            soft = rng.random() < self.cfg.blur
            for key in ("goal_frame", "frames"):
                out[key][b] = np.clip(out[key][b] * gain, 0, 255).astype(np.uint8)
            if soft:  # like a large camera frame area-shrunk (the tree's), not rendered small
                out["goal_frame"][b] = cv2.GaussianBlur(out["goal_frame"][b], (3, 3), 0.6)
                for i in range(m):
                    out["frames"][b, i] = cv2.GaussianBlur(out["frames"][b, i], (3, 3), 0.6)
        longest = int((~out["pad"]).sum(1).max())  # drop the columns that are padding only
        for key in ("frames", "pad", "action", "tdist", "track", "track_valid"):
            out[key] = out[key][:, :longest]
        return out


def flip(out: dict[str, np.ndarray], b: int, w: int) -> None:
    """Mirror sample ``b`` left-right: images, goal pixel, track, turn labels."""
    out["goal_frame"][b] = out["goal_frame"][b][:, ::-1]
    out["frames"][b] = out["frames"][b][:, :, ::-1]
    out["goal_px"][b, 0] = (w - 1) - out["goal_px"][b, 0]
    out["track"][b, :, 0] = (w - 1) / w - out["track"][b, :, 0]
    a = out["action"][b]
    left, right = a == LEFT, a == RIGHT
    a[left], a[right] = RIGHT, LEFT


def to_torch(batch: dict[str, np.ndarray], device: torch.device) -> dict[str, torch.Tensor]:
    return {k: torch.from_numpy(np.ascontiguousarray(v)).to(device) for k, v in batch.items()}


def losses(
    net: PixelNavNet, b: dict[str, torch.Tensor], cfg: TrainConfig
) -> tuple[torch.Tensor, dict[str, float]]:
    """The weighted loss of a batch and its parts (action accuracy and stop recall too)."""
    out = net(b["goal_frame"], b["goal_px"], b["frames"], b["pad"])
    real = ~b["pad"]
    weight = torch.ones(4, device=real.device)
    weight[STOP] = cfg.stop_weight
    logits, act = out["action"][real], b["action"][real]
    ce = F.cross_entropy(logits, act, weight=weight)
    td = F.mse_loss(out["tdist"][real], b["tdist"][real])
    tv = real & b["track_valid"]
    tr = (
        F.smooth_l1_loss(out["track"][tv], b["track"][tv], beta=0.1)
        if tv.any()
        else out["track"].sum() * 0.0
    )
    loss = ce + cfg.tdist_weight * td + cfg.track_weight * tr
    pred = logits.argmax(-1)
    stops = act == STOP
    parts = {
        "loss": float(loss.detach()),
        "ce": float(ce),
        "tdist": float(td),
        "track": float(tr),
        "acc": float((pred == act).float().mean()),
        "stop_recall": float((pred[stops] == STOP).float().mean()) if stops.any() else math.nan,
    }
    return loss, parts


def lr_at(step: int, cfg: TrainConfig) -> float:
    if step < cfg.warmup:
        return cfg.lr * (step + 1) / cfg.warmup
    f = (step - cfg.warmup) / max(1, cfg.steps - cfg.warmup)
    return 1e-5 + 0.5 * (cfg.lr - 1e-5) * (1 + math.cos(math.pi * min(1.0, f)))


def save_optimizer(opt: torch.optim.Optimizer, path: Path) -> None:
    """AdamW's per-parameter tensors as safetensors (no pickle)."""
    tensors = {}
    for i, st in opt.state_dict()["state"].items():
        for name, v in st.items():
            tensors[f"{i}.{name}"] = torch.as_tensor(v).detach().cpu().contiguous()
    save_file(tensors, str(path))


def load_optimizer(opt: torch.optim.Optimizer, path: Path) -> None:
    tensors = load_file(str(path))
    sd = opt.state_dict()
    state: dict[int, dict[str, torch.Tensor]] = {}
    for key, v in tensors.items():
        i, _, name = key.partition(".")
        state.setdefault(int(i), {})[name] = v
    sd["state"] = state
    opt.load_state_dict(sd)


def split_episodes(data: dict[str, np.ndarray], n_shards_eps: list[int], val_fraction: float):
    """(train, val) episode indices: the last shards (buildings) are validation."""
    n_val = max(1, int(round(len(n_shards_eps) * val_fraction)))
    if n_val >= len(n_shards_eps):
        raise TrainError(f"{len(n_shards_eps)} shard(s): too few for a validation split")
    cut = int(sum(n_shards_eps[:-n_val]))
    total = len(data["offsets"]) - 1
    return np.arange(cut), np.arange(cut, total)


def find_shards(data_dirs: list[Path]) -> list[Path]:
    """The shards of each folder in turn (validation takes the last ones: of the last folder)."""
    shards: list[Path] = []
    for d in data_dirs:
        shards += sorted(d.glob("shard_*.npz"))
    if len(shards) < 2:
        names = ", ".join(str(d) for d in data_dirs)
        raise TrainError(f"{names}: {len(shards)} shard(s); run `pmnav pixelnav gen` first")
    return shards


def init_weights(net: PixelNavNet, path: str) -> None:
    """Load ``path`` into ``net`` for fine-tuning; a shorter history's position table fills
    the first rows (the rest repeat its last row)."""
    w = Path(path)
    if not w.is_file():
        raise TrainError(f"--init {w}: no such weights file")
    sd = load_file(str(w))
    pos = sd.get("pos")
    if pos is not None and pos.shape[0] < net.pos.shape[0]:
        grown = pos[-1:].repeat(net.pos.shape[0], 1)
        grown[: pos.shape[0]] = pos
        sd["pos"] = grown
    try:
        net.load_state_dict(sd)
    except RuntimeError as err:
        raise TrainError(f"--init {w}: weights do not fit the model config: {err}") from None


def train(
    data_dir: str | Path | list, out_dir: str | Path, cfg: TrainConfig, progress: bool = True
) -> dict:
    """Train (or resume) into ``out_dir`` on the shards of ``data_dir`` (a folder or a
    list of them); returns the final state (history included)."""
    from tqdm import tqdm

    from pmnav_bt.pixelnav.plot import save_curves

    torch.set_num_threads(cfg.threads)
    dirs = [Path(d) for d in (data_dir if isinstance(data_dir, list | tuple) else [data_dir])]
    out = Path(out_dir)
    shards = find_shards(dirs)
    out.mkdir(parents=True, exist_ok=True)
    state_path = out / STATE_FILE
    state = {"step": 0, "history": [], "config": cfg.model_dump(mode="json"), "seconds": 0.0}
    if state_path.is_file():
        have = json.loads(state_path.read_text(encoding="utf-8"))
        if {k: v for k, v in have["config"].items() if k != "steps"} != {
            k: v for k, v in state["config"].items() if k != "steps"
        }:
            raise TrainError(f"{state_path}: another config trained here; use a new --out")
        state.update({k: have[k] for k in ("step", "history", "seconds")})
    data = load_shards(shards)
    per_shard = [int(len(np.load(p)["offsets"]) - 1) for p in shards]
    train_eps, val_eps = split_episodes(data, per_shard, cfg.val_fraction)
    device = pick_device()
    torch.manual_seed(cfg.seed)
    net = PixelNavNet(cfg.model).to(device)
    opt = torch.optim.AdamW(net.parameters(), lr=cfg.lr, weight_decay=cfg.weight_decay)
    if state["step"] > 0:
        net.load_state_dict(load_file(str(out / MODEL_FILE), device=str(device)))
        load_optimizer(opt, out / OPTIM_FILE)
    elif cfg.init:
        init_weights(net, cfg.init)
    tr_s, va_s = Sampler(data, train_eps, cfg), Sampler(data, val_eps, cfg)
    val_batches = [
        to_torch(va_s.batch(np.random.default_rng([cfg.seed, 10**9, i]), cfg.batch), device)
        for i in range(cfg.val_batches)
    ]
    state["data"] = {
        "shards": len(shards),
        "episodes": len(data["offsets"]) - 1,
        "frames": int(len(data["actions"])),
        "train_episodes": len(train_eps),
        "val_episodes": len(val_eps),
    }
    running: list[dict] = []
    bar = tqdm(total=cfg.steps, initial=state["step"], unit="step", disable=not progress)
    t0 = time.perf_counter() - state["seconds"]
    while state["step"] < cfg.steps:
        step = state["step"]
        for g in opt.param_groups:
            g["lr"] = lr_at(step, cfg)
        torch.manual_seed(cfg.seed * 1_000_003 + step)
        net.train()
        b = to_torch(tr_s.batch(np.random.default_rng([cfg.seed, step]), cfg.batch), device)
        loss, parts = losses(net, b, cfg)
        opt.zero_grad(set_to_none=True)
        loss.backward()
        torch.nn.utils.clip_grad_norm_(net.parameters(), 1.0)
        opt.step()
        running.append(parts)
        state["step"] = step + 1
        bar.update(1)
        if state["step"] % cfg.eval_every == 0 or state["step"] == cfg.steps:
            net.eval()
            with torch.no_grad():
                vals = [losses(net, vb, cfg)[1] for vb in val_batches]
            rec = {
                "step": state["step"],
                "train_loss": float(np.mean([r["loss"] for r in running])),
                "train_acc": float(np.mean([r["acc"] for r in running])),
                "val_loss": float(np.mean([v["loss"] for v in vals])),
                "val_acc": float(np.mean([v["acc"] for v in vals])),
                "val_stop_recall": float(np.nanmean([v["stop_recall"] for v in vals])),
                "val_track": float(np.mean([v["track"] for v in vals])),
                "val_tdist": float(np.mean([v["tdist"] for v in vals])),
                "lr": lr_at(step, cfg),
            }
            running = []
            state["seconds"] = time.perf_counter() - t0
            rec["seconds"] = state["seconds"]
            state["history"].append(rec)
            bar.set_postfix(val_loss=f"{rec['val_loss']:.3f}", val_acc=f"{rec['val_acc']:.3f}")
            save_checkpoint(net, opt, state, out)
            save_curves(state["history"], out / CURVES_FILE)
    bar.close()
    return state


def save_checkpoint(net: PixelNavNet, opt, state: dict, out: Path) -> None:
    """Model, optimizer and state, each written to a temporary file and moved in place."""
    sd = {k: v.detach().cpu().contiguous() for k, v in net.state_dict().items()}
    tmp = out / f".{MODEL_FILE}.tmp"
    save_file(sd, str(tmp), metadata={"format": "pt"})
    tmp.replace(out / MODEL_FILE)
    tmp = out / f".{OPTIM_FILE}.tmp"
    save_optimizer(opt, tmp)
    tmp.replace(out / OPTIM_FILE)
    tmp = out / f".{STATE_FILE}.tmp"
    tmp.write_text(json.dumps(state, indent=1), encoding="utf-8")
    tmp.replace(out / STATE_FILE)


def export(
    train_dir: str | Path,
    dest: str | Path,
    stop_threshold: float = 0.5,
    stop_steps: float | None = None,
) -> tuple[Path, Path]:
    """The trained model as ``dest.safetensors`` + ``dest.json`` (its model config and
    the policy's STOP rule: the probability threshold, and the steps-left one or None)."""
    train_dir, dest = Path(train_dir), Path(dest)
    state = json.loads((train_dir / STATE_FILE).read_text(encoding="utf-8"))
    sd = load_file(str(train_dir / MODEL_FILE))
    w = dest.with_suffix(".safetensors")
    j = dest.with_suffix(".json")
    w.parent.mkdir(parents=True, exist_ok=True)
    save_file(sd, str(w), metadata={"format": "pt"})
    w.chmod(0o644)  # package data: readable by every user
    meta = {
        "model": state["config"]["model"],
        "stop_threshold": stop_threshold,
        "stop_steps": stop_steps,
        "trained_steps": state["step"],
        "fine_tuned_from": state["config"].get("init", ""),
        "train_seconds": round(state.get("seconds", 0.0), 1),
        "data": state.get("data", {}),
        "final": state["history"][-1] if state["history"] else {},
    }
    j.write_text(json.dumps(meta, indent=1) + "\n", encoding="utf-8")
    return w, j


def preset(name: str) -> ModelConfig:
    if name not in PRESETS:
        raise TrainError(f"--model {name!r}: choose one of {', '.join(PRESETS)}")
    return PRESETS[name]
