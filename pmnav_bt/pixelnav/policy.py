"""The ``pixelnav`` back end: the trained network as a closed-loop pixel-goal policy.

It is both seams the tree uses for a grounded target:

- ``Refiner``: the direction of the goal pixel (the mask centre) and the range from depth,
  as the ``geometric`` refiner measures them (PixelNav gives actions, not metres);
- ``PixelGoalPolicy``: ``reset`` on a grounded frame, then ``act`` per frame: stop,
  forward 0.25 m or turn 30 deg, the goal pixel tracked in the frame, the steps left.
  STOP when its probability reaches ``stop_threshold`` or (``stop_steps``, when set) when
  the temporal-distance head expects at most that many steps left (both from the
  weights' JSON, chosen on validation buildings in closed loop), else the likeliest move;
  with ``no_reversal`` a turn never directly undoes the turn before it (imitation
  policies dither there).

The goal token is computed once per goal and each frame's token once, so a step costs one
frame encoding and one pass of the small transformer over the last ``history`` tokens.
The shipped model's history (64 frames) covers the skill's whole budget, so within it the
network always sees every frame since the goal frame. Past a full history (a smaller
model, or a longer run) the goal is re-seated on the last frame at the pixel where the
policy tracked it there (training shows the network such re-seated goals), and the
history starts afresh after it; a goal tracked out of view keeps the old goal and the
window slides.
Weights: safetensors plus a JSON of the model config; the shipped small model is the
default. Call from the worker: a step takes milliseconds, and the policy keeps state.
"""

from __future__ import annotations

import json
import threading
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from pmnav_bt.errors import BackendError
from pmnav_bt.perception.refiners.geometric import GeometricRefiner
from pmnav_bt.pixelnav.dataset import ACTIONS, LEFT, MAX_STEPS, RIGHT, STOP
from pmnav_bt.pixelnav.frames import scale_pixel, shrink
from pmnav_bt.seams import Detection, Observation, PolicyStep, Refinement

if TYPE_CHECKING:  # pragma: no cover
    from pmnav_bt.backends import BackendDeps

SHIPPED = "pixelnav_small"


def shipped_weights() -> Path:
    """The shipped small model's ``.safetensors`` (its ``.json`` lies beside it)."""
    return Path(str(resources.files("pmnav_bt.pixelnav") / "weights" / f"{SHIPPED}.safetensors"))


class PixelNavPolicy:
    """A trained PixelNav network behind the Refiner and PixelGoalPolicy seams."""

    gives_range = True
    drives_approach = True  # a PixelGoalPolicy: the tree approaches with PolicyApproach
    max_steps = MAX_STEPS

    def __init__(
        self,
        net,
        device=None,
        stop_threshold: float = 0.5,
        no_reversal: bool = True,
        stop_steps: float | None = None,
    ):
        import torch

        self.net = net.eval()
        self.stop_threshold = stop_threshold
        self.stop_steps = stop_steps
        self.no_reversal = no_reversal
        self._last_action = STOP
        self.cfg = net.cfg
        self.device = device or torch.device("cpu")
        self._geometric = GeometricRefiner()
        self._lock = threading.Lock()
        self._goal_tok = None
        self._tokens: list = []
        self._last_track = (0.0, 0.0)
        self._last_frame = None
        self.last_stop_prob = 0.0  # the last step's STOP probability (for calibration)

    @classmethod
    def load(cls, weights: str | Path | None = None, device: str | None = None) -> PixelNavPolicy:
        """The network from ``weights`` (``.safetensors`` with a ``.json`` of its config
        beside it; default: the shipped small model)."""
        import torch
        from safetensors.torch import load_file

        from pmnav_bt.pixelnav.model import ModelConfig, PixelNavNet

        w = Path(weights) if weights else shipped_weights()
        meta = w.with_suffix(".json")
        if not w.is_file() or not meta.is_file():
            raise BackendError(
                f"refiner.weights: {w} (and {meta.name} beside it) not found; train one with "
                "`pmnav pixelnav train` and `pmnav pixelnav export`"
            )
        try:
            info = json.loads(meta.read_text(encoding="utf-8"))
            cfg = ModelConfig.model_validate(info["model"])
            stop = float(info.get("stop_threshold", 0.5))
            no_reversal = bool(info.get("no_reversal", True))
            stop_steps = info.get("stop_steps")
            stop_steps = None if stop_steps is None else float(stop_steps)
        except (ValueError, KeyError, TypeError) as err:
            raise BackendError(f"{meta}: not a PixelNav model config ({err})") from None
        dev = torch.device(device) if device else torch.device("cpu")
        net = PixelNavNet(cfg)
        try:
            net.load_state_dict(load_file(str(w), device=str(dev)))
        except (RuntimeError, OSError) as err:
            raise BackendError(
                f"{w}: weights do not fit the config in {meta.name}: {err}"
            ) from None
        return cls(net.to(dev), dev, stop, no_reversal, stop_steps)

    # -- Refiner ------------------------------------------------------------------------------

    def refine(self, obs: Observation, goal: Detection) -> Refinement:
        """Bearing of the goal pixel, range from depth (as ``geometric``)."""
        return self._geometric.refine(obs, goal)

    # -- PixelGoalPolicy ----------------------------------------------------------------------

    def _frame(self, obs: Observation):
        import torch

        small = shrink(obs.rgb, self.cfg.width, self.cfg.height)
        return torch.from_numpy(np.ascontiguousarray(small)).to(self.device)

    def _seat(self, frame, px: tuple[float, float]) -> None:
        import torch

        gp = torch.tensor([px], dtype=torch.float32, device=self.device)
        self._goal_tok = self.net.encode_goal(frame.unsqueeze(0), gp)
        self._tokens = []
        self._last_track = px
        self._last_action = STOP

    def reset(self, obs: Observation, goal: Detection) -> None:
        """Start a new approach to ``goal`` (its mask centre) as seen in ``obs``."""
        import torch

        px = scale_pixel(goal.centre, obs.intrinsics, self.cfg.width, self.cfg.height)
        with self._lock, torch.inference_mode():
            self._seat(self._frame(obs), px)

    def act(self, obs: Observation) -> PolicyStep:
        """The action for this frame, the tracked goal pixel and the steps it expects."""
        import torch

        if self._goal_tok is None:
            raise BackendError("pixelnav: act() before reset(): no goal")
        cfg = self.cfg
        with self._lock, torch.inference_mode():
            frame = self._frame(obs)
            if len(self._tokens) >= cfg.history:
                u, v = self._last_track  # where the last frame showed the goal
                if 0 <= u < cfg.width and 0 <= v < cfg.height:
                    self._seat(self._last_frame, (u, v))
                else:
                    self._tokens = self._tokens[-(cfg.history - 1) :]
            self._last_frame = frame
            self._tokens.append(self.net.encode_frames(frame.view(1, 1, *frame.shape))[:, 0])
            out = self.net.decode(self._goal_tok, torch.stack(self._tokens, dim=1))
            probs = out["action"][0, -1].softmax(-1)
            # the training targets' range: -1..2 frame widths/heights
            track = np.clip(out["track"][0, -1].cpu().numpy(), -1.0, 2.0) * (cfg.width, cfg.height)
            steps = float(out["tdist"][0, -1]) * _tdist_scale()
        self._last_track = (float(track[0]), float(track[1]))
        self.last_stop_prob = float(probs[STOP])
        k = obs.intrinsics
        u = (track[0] + 0.5) * k.width / cfg.width - 0.5
        v = (track[1] + 0.5) * k.height / cfg.height - 0.5
        # STOP once it is likely enough (the threshold is calibrated on validation
        # buildings and kept in the weights' JSON), else the likeliest move.
        near = self.stop_steps is not None and steps <= self.stop_steps
        if float(probs[STOP]) >= self.stop_threshold or near:
            action = ACTIONS[STOP]
        else:
            moves = probs.clone()
            moves[STOP] = -1.0
            if self.no_reversal and self._last_action in (LEFT, RIGHT):
                moves[RIGHT if self._last_action == LEFT else LEFT] = -1.0  # no dithering
            action = ACTIONS[int(moves.argmax())]
        self._last_action = ACTIONS.index(action)
        return PolicyStep(action, (float(u), float(v)), max(0.0, steps))


def _tdist_scale() -> float:
    from pmnav_bt.pixelnav.model import TDIST_SCALE

    return TDIST_SCALE


def build(deps: BackendDeps) -> PixelNavPolicy:
    """The ``pixelnav`` back end (registry factory): ``refiner.weights`` or the shipped model."""
    from pmnav_bt.pixelnav.train import pick_device

    return PixelNavPolicy.load(deps.config.refiner.weights or None, str(pick_device()))
