"""The training data's format: action indices, goal kinds, episodes packed into shards.

A shard is one ``.npz``: the per-step arrays of its episodes concatenated (``frames``
uint8 (N, H, W, 3), ``actions``, ``tdist``, ``track``, ``track_valid``) with ``offsets``
(E + 1) marking where each episode starts, and the per-episode arrays (``goal_px``,
``goal_mask``, ``kind``, ``goal``, ``start``, ``geodesic``). ``pmnav pixelnav gen``
(``pmnav_bt.experiments.pixelnav_data``) writes them in the simulator; training reads
them here, without the simulator.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pmnav_bt.errors import PmNavError
from pmnav_bt.seams import DiscreteAction

# Action indices of the policy (the order of its action head).
ACTIONS = (
    DiscreteAction.STOP,
    DiscreteAction.FORWARD,
    DiscreteAction.TURN_LEFT,
    DiscreteAction.TURN_RIGHT,
)
STOP, FORWARD, LEFT, RIGHT = range(4)
KINDS = ("door", "sign", "floor")
MAX_STEPS = 64  # the skill's budget (issue 10): actions including the stop


class ShardError(PmNavError):
    """Shards that cannot be read as training data."""


@dataclass
class Episode:
    """One expert rollout (arrays per step, the rest per episode)."""

    frames: np.ndarray  # (T, H, W, 3) uint8
    actions: np.ndarray  # (T,) int8, the expert's label at each frame (last: STOP)
    tdist: np.ndarray  # (T,) int16, steps left to the stop
    track: np.ndarray  # (T, 2) float32, goal pixel / (W, H) in each frame
    track_valid: np.ndarray  # (T,) bool: the goal point is in front of the camera
    goal_px: np.ndarray  # (2,) float32, the goal pixel in the first frame (policy px)
    goal_mask: np.ndarray  # (H, W) bool, in the first frame
    kind: int  # index into KINDS
    goal: np.ndarray  # (3,) map point
    start: np.ndarray  # (3,) x, y, yaw
    geodesic: float  # m from the start to the stop region


def pack(eps: list[Episode], bseed: int) -> dict[str, np.ndarray]:
    """Episodes -> the shard's flat arrays (per-step arrays concatenated, with offsets)."""
    offsets = np.cumsum([0] + [len(e.actions) for e in eps]).astype(np.int64)
    return {
        "frames": np.concatenate([e.frames for e in eps]),
        "actions": np.concatenate([e.actions for e in eps]),
        "tdist": np.concatenate([e.tdist for e in eps]),
        "track": np.concatenate([e.track for e in eps]),
        "track_valid": np.concatenate([e.track_valid for e in eps]),
        "offsets": offsets,
        "goal_px": np.stack([e.goal_px for e in eps]),
        "goal_mask": np.stack([e.goal_mask for e in eps]),
        "kind": np.array([e.kind for e in eps], np.int8),
        "goal": np.stack([e.goal for e in eps]),
        "start": np.stack([e.start for e in eps]),
        "geodesic": np.array([e.geodesic for e in eps], np.float32),
        "building_seed": np.array([bseed], np.int64),
    }


def shard_path(out: Path, shard: int) -> Path:
    return out / f"shard_{shard:05d}.npz"


def load_shards(paths: list[Path]) -> dict[str, np.ndarray]:
    """Shards -> one set of arrays (episode offsets made global)."""
    parts = [dict(np.load(p)) for p in paths]
    if not parts:
        raise ShardError("no shards to load")
    out: dict[str, np.ndarray] = {}
    per_step = ("frames", "actions", "tdist", "track", "track_valid")
    per_ep = ("goal_px", "goal_mask", "kind", "goal", "start", "geodesic")
    for key in per_step + per_ep:
        out[key] = np.concatenate([d[key] for d in parts])
    offs, base = [0], 0
    for d in parts:
        o = d["offsets"]
        offs.extend((o[1:] + base).tolist())
        base += int(o[-1])
    out["offsets"] = np.array(offs, np.int64)
    return out
