"""The PixelNav network, in the shape of Cai et al. (CVPR 2024), sized by a config.

- goal encoder: a CNN over 4 channels, the goal frame's RGB and a filled square around
  the goal pixel, to one goal token;
- history encoder: a CNN over each frame of the history (RGB), one token per frame;
- a causal transformer over [goal token, frame tokens] (learned positions);
- heads on each frame's output: the action (stop, forward, turn left, turn right), the
  temporal distance to the goal (steps, scaled), and goal tracking (the goal pixel in
  that frame, as a fraction of the width and height).

The CNNs flatten their last feature map instead of pooling it, so the tokens keep where
things are in the image (goal tracking needs it). ``SMALL`` trains on a 2-core CPU,
``LARGE`` is for a GPU.
"""

from __future__ import annotations

import torch
from pydantic import BaseModel, ConfigDict, Field
from torch import nn

N_ACTIONS = 4
TDIST_SCALE = 32.0  # temporal distance targets are steps / TDIST_SCALE


class ModelConfig(BaseModel):
    """Sizes of the network (saved beside its weights)."""

    model_config = ConfigDict(extra="forbid")

    width: int = Field(64, ge=16, description="frame width (px)")
    height: int = Field(48, ge=12, description="frame height (px)")
    channels: tuple[int, ...] = Field((16, 32, 64, 64), description="CNN widths, stride 2 each")
    dim: int = Field(128, ge=8, description="token size")
    layers: int = Field(2, ge=1)
    heads: int = Field(4, ge=1)
    ff: int = Field(256, ge=8, description="transformer feed-forward width")
    history: int = Field(64, ge=1, description="frames the transformer sees")
    goal_half: int = Field(2, ge=0, description="goal square: +- this many px")
    dropout: float = Field(0.1, ge=0.0, lt=1.0)


# The shipped presets see the whole 64-step budget (as the paper's decoder does): a
# 16-frame window slid or re-seated mid-approach, and the network, which had learned that a
# full window means a late step, stopped short there.
SMALL = ModelConfig()
LARGE = ModelConfig(channels=(32, 64, 128, 128), dim=256, layers=4, heads=8, ff=1024, history=64)
TINY = ModelConfig(channels=(4, 8), dim=16, layers=1, heads=2, ff=32, history=4, dropout=0.0)
PRESETS = {"tiny": TINY, "small": SMALL, "large": LARGE}


def _cnn(cfg: ModelConfig, c_in: int) -> nn.Sequential:
    layers: list[nn.Module] = []
    h, w = cfg.height, cfg.width
    for i, c in enumerate(cfg.channels):
        k = 5 if i == 0 else 3
        layers += [nn.Conv2d(c_in, c, k, stride=2, padding=k // 2), nn.GroupNorm(1, c), nn.GELU()]
        c_in, h, w = c, (h + 1) // 2, (w + 1) // 2
    layers += [nn.Flatten(), nn.Linear(c_in * h * w, cfg.dim), nn.LayerNorm(cfg.dim)]
    return nn.Sequential(*layers)


def goal_channel(goal_px: torch.Tensor, cfg: ModelConfig) -> torch.Tensor:
    """(B, 2) goal pixels (x, y) -> (B, 1, H, W) filled squares of +- ``goal_half`` px."""
    ys = torch.arange(cfg.height, device=goal_px.device).view(1, -1, 1)
    xs = torch.arange(cfg.width, device=goal_px.device).view(1, 1, -1)
    gx = goal_px[:, 0].round().view(-1, 1, 1)
    gy = goal_px[:, 1].round().view(-1, 1, 1)
    r = cfg.goal_half
    sq = ((xs - gx).abs() <= r) & ((ys - gy).abs() <= r)
    return sq.unsqueeze(1).float()


def normalise(frames: torch.Tensor) -> torch.Tensor:
    """uint8 (..., H, W, 3) -> float (..., 3, H, W) in about [-1, 1]."""
    x = frames.float().div(127.5).sub(1.0)
    return x.movedim(-1, -3)


class PixelNavNet(nn.Module):
    """Goal frame + goal pixel + frame history -> per-frame action logits, temporal
    distance and goal track."""

    def __init__(self, cfg: ModelConfig):
        super().__init__()
        self.cfg = cfg
        self.goal_encoder = _cnn(cfg, 4)
        self.frame_encoder = _cnn(cfg, 3)
        self.pos = nn.Parameter(torch.zeros(cfg.history + 1, cfg.dim))
        nn.init.normal_(self.pos, std=0.02)
        layer = nn.TransformerEncoderLayer(
            cfg.dim,
            cfg.heads,
            cfg.ff,
            cfg.dropout,
            activation="gelu",
            batch_first=True,
            norm_first=True,
        )
        self.transformer = nn.TransformerEncoder(layer, cfg.layers, enable_nested_tensor=False)
        self.norm = nn.LayerNorm(cfg.dim)
        self.action_head = nn.Linear(cfg.dim, N_ACTIONS)
        self.tdist_head = nn.Linear(cfg.dim, 1)
        self.track_head = nn.Linear(cfg.dim, 2)

    def encode_goal(self, goal_frame: torch.Tensor, goal_px: torch.Tensor) -> torch.Tensor:
        """(B, H, W, 3) uint8 + (B, 2) px -> (B, dim) goal tokens."""
        x = torch.cat([normalise(goal_frame), goal_channel(goal_px, self.cfg)], dim=1)
        return self.goal_encoder(x)

    def encode_frames(self, frames: torch.Tensor, pad: torch.Tensor | None = None) -> torch.Tensor:
        """(B, T, H, W, 3) uint8 -> (B, T, dim) frame tokens; with ``pad`` (B, T), only
        the real frames are encoded (padding tokens are zeros, masked out later)."""
        b, t = frames.shape[:2]
        if pad is None:
            return self.frame_encoder(normalise(frames.flatten(0, 1))).view(b, t, -1)
        real = ~pad
        tok = self.frame_encoder(normalise(frames[real]))
        out = tok.new_zeros(b, t, tok.shape[-1])
        out[real] = tok
        return out

    def decode(
        self, goal_tok: torch.Tensor, frame_tok: torch.Tensor, pad: torch.Tensor | None = None
    ) -> dict[str, torch.Tensor]:
        """Goal tokens (B, dim) + frame tokens (B, T, dim) -> per-frame outputs:
        ``action`` (B, T, 4) logits, ``tdist`` (B, T) scaled steps, ``track`` (B, T, 2).
        ``pad``: (B, T) True where a frame is padding (after the real ones)."""
        t = frame_tok.shape[1]
        if t > self.cfg.history:
            raise ValueError(f"{t} frames: the model sees at most {self.cfg.history}")
        x = torch.cat([goal_tok.unsqueeze(1), frame_tok], dim=1) + self.pos[: t + 1]
        causal = nn.Transformer.generate_square_subsequent_mask(t + 1, device=x.device)
        key_pad = None
        if pad is not None:
            key_pad = torch.cat([torch.zeros_like(pad[:, :1]), pad], dim=1)
            key_pad = torch.zeros_like(key_pad, dtype=x.dtype).masked_fill(key_pad, float("-inf"))
        y = self.norm(self.transformer(x, mask=causal, src_key_padding_mask=key_pad))[:, 1:]
        return {
            "action": self.action_head(y),
            "tdist": self.tdist_head(y).squeeze(-1),
            "track": self.track_head(y),
        }

    def forward(
        self,
        goal_frame: torch.Tensor,
        goal_px: torch.Tensor,
        frames: torch.Tensor,
        pad: torch.Tensor | None = None,
    ) -> dict[str, torch.Tensor]:
        return self.decode(
            self.encode_goal(goal_frame, goal_px), self.encode_frames(frames, pad), pad
        )
