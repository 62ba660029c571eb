"""The PixelNav network: output shapes, causality, learning a fixed batch, and weights
that survive a safetensors round trip (export included)."""

from __future__ import annotations

import json

import pytest

torch = pytest.importorskip("torch")

from safetensors.torch import load_file, save_file  # noqa: E402

from pmnav_bt.pixelnav.model import TINY, PixelNavNet, goal_channel  # noqa: E402


def batch(b=3, t=TINY.history, seed=0):
    g = torch.Generator().manual_seed(seed)
    frames = torch.randint(0, 256, (b, t, TINY.height, TINY.width, 3), generator=g)
    return (
        frames[:, 0].to(torch.uint8),
        torch.tensor([[10.0, 20.0], [0.0, 0.0], [63.0, 47.0]][:b]),
        frames.to(torch.uint8),
    )


def net(seed=0):
    torch.manual_seed(seed)
    return PixelNavNet(TINY).eval()


def test_output_shapes():
    out = net()(*batch())
    assert out["action"].shape == (3, TINY.history, 4)
    assert out["tdist"].shape == (3, TINY.history)
    assert out["track"].shape == (3, TINY.history, 2)


def test_goal_channel_is_a_filled_square_at_the_goal_pixel():
    ch = goal_channel(torch.tensor([[10.0, 20.0]]), TINY)[0, 0]
    ys, xs = torch.nonzero(ch, as_tuple=True)
    r = TINY.goal_half
    assert (xs.min(), xs.max(), ys.min(), ys.max()) == (10 - r, 10 + r, 20 - r, 20 + r)
    assert ch.sum() == (2 * r + 1) ** 2


def test_the_transformer_is_causal_and_the_goal_matters():
    m = net()
    gf, gp, frames = batch()
    with torch.no_grad():
        a = m(gf, gp, frames)["action"]
        later = frames.clone()
        later[:, -1] = 255 - later[:, -1]
        b = m(gf, gp, later)["action"]
        c = m(gf, gp + 15.0, frames)["action"]
    assert torch.allclose(a[:, :-1], b[:, :-1], atol=1e-5)  # the past ignores the future
    assert not torch.allclose(a[:, -1], b[:, -1])
    assert not torch.allclose(a, c)  # a moved goal pixel changes the answers


def test_padding_leaves_the_real_frames_alone():
    m = net()
    gf, gp, frames = batch()
    pad = torch.zeros(3, TINY.history, dtype=torch.bool)
    pad[:, -1] = True
    with torch.no_grad():
        a = m(gf, gp, frames, pad)["action"]
        frames2 = frames.clone()
        frames2[:, -1] = 0
        b = m(gf, gp, frames2, pad)["action"]
    assert torch.allclose(a[:, :-1], b[:, :-1], atol=1e-5)


def test_a_tiny_model_overfits_a_fixed_batch():
    from torch.nn import functional as F

    torch.manual_seed(0)
    m = PixelNavNet(TINY).train()
    gf, gp, frames = batch(b=3)
    target = torch.tensor([[1, 2, 1, 0], [3, 3, 1, 0], [1, 1, 1, 0]])
    opt = torch.optim.Adam(m.parameters(), lr=3e-3)
    losses = []
    for _ in range(80):
        loss = F.cross_entropy(m(gf, gp, frames)["action"].flatten(0, 1), target.flatten())
        opt.zero_grad()
        loss.backward()
        opt.step()
        losses.append(loss.item())
    assert losses[-1] < 0.2 * losses[0]
    with torch.no_grad():
        assert (m.eval()(gf, gp, frames)["action"].argmax(-1) == target).all()


def test_weights_round_trip_through_safetensors(tmp_path):
    m = net(1)
    path = tmp_path / "w.safetensors"
    save_file({k: v.contiguous() for k, v in m.state_dict().items()}, str(path))
    m2 = PixelNavNet(TINY).eval()
    m2.load_state_dict(load_file(str(path)))
    args = batch()
    with torch.no_grad():
        for k, v in m(*args).items():
            assert torch.equal(v, m2(*args)[k])


def test_export_writes_weights_and_their_config(tmp_path):
    from pmnav_bt.pixelnav.policy import PixelNavPolicy
    from pmnav_bt.pixelnav.train import STATE_FILE, TrainConfig, export, save_checkpoint

    m = net(2)
    cfg = TrainConfig(model=TINY)
    opt = torch.optim.AdamW(m.parameters())
    state = {"step": 0, "history": [], "config": cfg.model_dump(mode="json"), "seconds": 0.0}
    save_checkpoint(m, opt, state, tmp_path)
    assert (tmp_path / STATE_FILE).is_file()
    w, j = export(tmp_path, tmp_path / "out" / "model.safetensors")
    assert json.loads(j.read_text())["model"]["dim"] == TINY.dim
    loaded = PixelNavPolicy.load(w).net
    args = batch()
    with torch.no_grad():
        assert torch.equal(m(*args)["action"], loaded(*args)["action"])


def test_padded_frames_are_not_encoded_and_real_ones_encode_as_without_padding():
    m = net()
    gf, gp, frames = batch()
    pad = torch.zeros(3, TINY.history, dtype=torch.bool)
    pad[1:, 2:] = True
    with torch.no_grad():
        tok = m.encode_frames(frames, pad)
        full = m.encode_frames(frames)
    assert torch.allclose(tok[~pad], full[~pad], atol=1e-5)
    assert torch.equal(tok[pad], torch.zeros_like(tok[pad]))


def test_fine_tuning_starts_from_weights_of_a_shorter_history(tmp_path):
    from pmnav_bt.pixelnav.train import TrainError, init_weights

    short = net(3)
    path = tmp_path / "w.safetensors"
    save_file({k: v.contiguous() for k, v in short.state_dict().items()}, str(path))
    longer = PixelNavNet(TINY.model_copy(update={"history": 2 * TINY.history}))
    init_weights(longer, str(path))
    n = TINY.history + 1
    assert torch.equal(longer.pos[:n], short.pos)
    assert torch.equal(longer.pos[n:], short.pos[-1:].expand(TINY.history, -1))
    assert torch.equal(longer.frame_encoder[0].weight, short.frame_encoder[0].weight)
    with pytest.raises(TrainError, match="--init"):
        init_weights(PixelNavNet(TINY.model_copy(update={"dim": 32})), str(path))
