"""Training data from the simulator: a seed makes the same shard; the expert's episodes
are what training assumes (goal 1-5 m away, a stop at the end, within 1 m of the goal);
gen resumes; the sampler flips turns with the image."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pmnav_bt.experiments.pixelnav_data import (
    HELDOUT_BUILDING_SEEDS,
    TRAIN_BUILDING_SEEDS,
    DataConfig,
    DataGenError,
    building_seed,
    generate,
    generate_shard,
)
from pmnav_bt.pixelnav.dataset import FORWARD, LEFT, MAX_STEPS, RIGHT, STOP, load_shards

CFG = DataConfig(seed=3, shards=2, episodes_per_shard=2)


@pytest.fixture(scope="module")
def shard():
    return generate_shard(CFG, 0)


def test_a_seed_makes_the_same_shard(shard):
    again = generate_shard(CFG, 0)
    assert shard.keys() == again.keys()
    for k in shard:
        assert np.array_equal(shard[k], again[k]), k
    other = generate_shard(DataConfig(seed=4, shards=2, episodes_per_shard=2), 0)
    assert not np.array_equal(shard["start"], other["start"])


def test_expert_episodes_end_in_a_stop_near_a_goal_1_to_5_m_away(shard):
    offs = shard["offsets"]
    assert len(offs) == 3 and offs[-1] == len(shard["actions"]) == len(shard["frames"])
    assert shard["frames"].shape[1:] == (CFG.height, CFG.width, 3)
    for e in range(2):
        a = shard["actions"][offs[e] : offs[e + 1]]
        assert a[-1] == STOP and (a[:-1] != STOP).all() and len(a) <= MAX_STEPS
        assert set(a[:-1]) <= {FORWARD, LEFT, RIGHT}
        td = shard["tdist"][offs[e] : offs[e + 1]]
        assert list(td) == list(range(len(a) - 1, -1, -1))
        d = math.dist(shard["start"][e][:2], shard["goal"][e][:2])
        assert CFG.min_dist <= d <= CFG.max_dist
        # the first frame's track is the goal pixel itself
        u, v = shard["track"][offs[e]] * (CFG.width, CFG.height)
        assert (u, v) == pytest.approx(tuple(shard["goal_px"][e]), abs=1e-3)
        assert shard["goal_mask"][e].any()


def test_training_and_held_out_buildings_never_meet():
    train = {building_seed(DataConfig(seed=s), i) for s in range(3) for i in range(50)}
    held = {building_seed(DataConfig(seed=s, heldout=True), i) for s in range(3) for i in range(50)}
    assert all(TRAIN_BUILDING_SEEDS[0] <= b < TRAIN_BUILDING_SEEDS[1] for b in train)
    assert all(HELDOUT_BUILDING_SEEDS[0] <= b < HELDOUT_BUILDING_SEEDS[1] for b in held)


def test_gen_resumes_and_refuses_another_config(tmp_path, monkeypatch, shard):
    import pmnav_bt.experiments.pixelnav_data as data

    made = []
    monkeypatch.setattr(data, "generate_shard", lambda cfg, i: made.append(i) or shard)
    generate(CFG, tmp_path, progress=False)
    assert made == [0, 1]
    (tmp_path / "shard_00001.npz").unlink()
    generate(CFG, tmp_path, progress=False)
    assert made == [0, 1, 1]  # only the missing one
    loaded = load_shards(sorted(tmp_path.glob("shard_*.npz")))
    assert len(loaded["offsets"]) == 5 and loaded["offsets"][-1] == 2 * len(shard["actions"])
    with pytest.raises(DataGenError, match="another config"):
        generate(DataConfig(seed=4, shards=2, episodes_per_shard=2), tmp_path, progress=False)


def test_the_sampler_flips_turns_with_the_image(shard):
    from pmnav_bt.pixelnav.model import TINY
    from pmnav_bt.pixelnav.train import Sampler, TrainConfig

    d = dict(shard)
    eps = np.arange(2)
    plain = Sampler(d, eps, TrainConfig(model=TINY, flip=0.0, reseat=0.0))
    flipped = Sampler(d, eps, TrainConfig(model=TINY, flip=1.0, reseat=0.0))
    a = plain.batch(np.random.default_rng(0), 4)
    b = flipped.batch(np.random.default_rng(0), 4)
    real = ~a["pad"]
    swap = {STOP: STOP, FORWARD: FORWARD, LEFT: RIGHT, RIGHT: LEFT}
    assert [swap[x] for x in a["action"][real]] == list(b["action"][real])
    assert np.allclose(b["goal_px"][:, 0], (TINY.width - 1) - a["goal_px"][:, 0])


def test_sampler_batches_end_at_the_longest_window(shard):
    from pmnav_bt.pixelnav.model import TINY
    from pmnav_bt.pixelnav.train import Sampler, TrainConfig

    d = dict(shard)
    model = TINY.model_copy(update={"history": MAX_STEPS})
    s = Sampler(d, np.arange(2), TrainConfig(model=model))
    longest = int(np.diff(d["offsets"]).max())
    for seed in range(3):
        b = s.batch(np.random.default_rng(seed), 4)
        t = b["frames"].shape[1]
        assert t <= longest
        assert (~b["pad"][:, -1]).any()  # no column of padding only
        for key in ("pad", "action", "tdist", "track", "track_valid"):
            assert b[key].shape[1] == t
