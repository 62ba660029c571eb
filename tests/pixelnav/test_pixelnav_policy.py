"""The ``pixelnav`` back end's contract: the Refiner and PixelGoalPolicy seams, the goal
pixel in and out in the observation's pixels, a history longer than the network's window,
the registry with the shipped weights, and clear errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from pmnav_bt.errors import BackendError  # noqa: E402
from pmnav_bt.pixelnav.model import TINY, PixelNavNet  # noqa: E402
from pmnav_bt.pixelnav.policy import PixelNavPolicy, shipped_weights  # noqa: E402
from pmnav_bt.seams import (  # noqa: E402
    CameraIntrinsics,
    Detection,
    DiscreteAction,
    Observation,
    PixelGoalPolicy,
    PolicyStep,
    Pose2D,
    Refiner,
)

K = CameraIntrinsics.from_hfov(320, 240, math.radians(60))


def obs(seed=0, depth=3.0):
    rgb = np.random.default_rng(seed).integers(0, 256, (240, 320, 3), dtype=np.uint8)
    return Observation(rgb, Pose2D(0, 0, 0), 0.0, K, depth=np.full((240, 320), depth, np.float32))


def goal(u=240.0, v=100.0):
    mask = np.zeros((240, 320), bool)
    mask[int(v) - 10 : int(v) + 11, int(u) - 10 : int(u) + 11] = True
    return Detection("door", (u - 10, v - 10, u + 10, v + 10), 0.9, mask=mask)


@pytest.fixture
def policy():
    torch.manual_seed(0)
    return PixelNavPolicy(PixelNavNet(TINY))


def test_it_is_a_refiner_and_a_pixel_goal_policy(policy):
    assert isinstance(policy, Refiner) and isinstance(policy, PixelGoalPolicy)
    assert policy.max_steps == 64


def test_refine_gives_the_goal_pixels_bearing_and_the_depth_range(policy):
    r = policy.refine(obs(), goal(240.0))
    assert r.bearing == pytest.approx(K.pixel_bearing(240.0))
    assert r.bearing < 0  # right of the axis
    assert r.range == pytest.approx(math.hypot(3.0, 3.0 * math.tan(-r.bearing)), rel=1e-3)


def test_act_needs_a_goal_first(policy):
    with pytest.raises(BackendError, match="reset"):
        policy.act(obs())


def test_each_step_answers_an_action_and_a_tracked_pixel_in_the_frames_pixels(policy):
    policy.reset(obs(0), goal())
    for i in range(3 * TINY.history):  # past the network's window: it slides or re-seats
        step = policy.act(obs(i))
        assert isinstance(step, PolicyStep) and isinstance(step.action, DiscreteAction)
        assert step.steps_to_goal >= 0.0
        u, v = step.goal_pixel
        assert -320 <= u <= 2 * 320 and -240 <= v <= 2 * 240
        assert len(policy._tokens) <= TINY.history


def test_the_answer_depends_on_the_goal_pixel_not_on_earlier_episodes(policy):
    policy.reset(obs(0), goal(240.0))
    first = [policy.act(obs(i)) for i in range(3)]
    policy.reset(obs(0), goal(40.0))
    policy.reset(obs(0), goal(240.0))  # a reset forgets everything before it
    again = [policy.act(obs(i)) for i in range(3)]
    assert first == again


def test_the_registry_builds_pixelnav_with_the_shipped_weights():
    from pmnav_bt.backends import BackendDeps
    from pmnav_bt.config import load_config
    from pmnav_bt.map.catalogue import load_building
    from pmnav_bt.map.priori_map import parse_building
    from pmnav_bt.registry import REFINERS

    assert shipped_weights().is_file() and shipped_weights().with_suffix(".json").is_file()
    cfg = load_config(overrides=["refiner.backend=pixelnav"])
    pm = parse_building(load_building("fig2_hospital"))
    built = REFINERS.build("pixelnav", BackendDeps(config=cfg, pm=pm))
    assert isinstance(built, PixelNavPolicy) and built.cfg.width == 64
    built.reset(obs(), goal())
    assert isinstance(built.act(obs()).action, DiscreteAction)


def test_missing_weights_name_the_setting(tmp_path):
    with pytest.raises(BackendError, match="refiner.weights"):
        PixelNavPolicy.load(tmp_path / "none.safetensors")


def test_the_stop_threshold_decides_when_to_stop(policy):
    policy.reset(obs(0), goal())
    policy.stop_threshold = 0.0
    assert policy.act(obs(1)).action == DiscreteAction.STOP
    policy.stop_threshold = 1.01
    moves = {policy.act(obs(i)).action for i in range(6)}
    assert DiscreteAction.STOP not in moves


def test_export_keeps_the_stop_threshold(tmp_path):
    from pmnav_bt.pixelnav.train import TrainConfig, export, save_checkpoint

    torch.manual_seed(0)
    m = PixelNavNet(TINY)
    state = {"step": 1, "history": [], "config": TrainConfig(model=TINY).model_dump(mode="json")}
    save_checkpoint(m, torch.optim.AdamW(m.parameters()), state, tmp_path)
    w, _ = export(tmp_path, tmp_path / "w.safetensors", stop_threshold=0.25)
    assert PixelNavPolicy.load(w).stop_threshold == 0.25


def test_the_steps_left_rule_stops_when_the_distance_head_says_the_goal_is_near(policy):
    policy.reset(obs(0), goal())
    policy.stop_threshold = 1.01  # never by the STOP probability
    policy.stop_steps = None
    assert DiscreteAction.STOP not in {policy.act(obs(i)).action for i in range(4)}
    step = policy.act(obs(5))
    policy.reset(obs(0), goal())
    policy.stop_steps = step.steps_to_goal + 100.0  # any estimate is within reach
    assert policy.act(obs(1)).action == DiscreteAction.STOP


def test_export_keeps_the_steps_left_rule(tmp_path):
    from pmnav_bt.pixelnav.train import TrainConfig, export, save_checkpoint

    torch.manual_seed(0)
    m = PixelNavNet(TINY)
    state = {"step": 1, "history": [], "config": TrainConfig(model=TINY).model_dump(mode="json")}
    save_checkpoint(m, torch.optim.AdamW(m.parameters()), state, tmp_path)
    w, _ = export(tmp_path, tmp_path / "w.safetensors", stop_threshold=0.3, stop_steps=1.5)
    assert PixelNavPolicy.load(w).stop_steps == 1.5
    w, _ = export(tmp_path, tmp_path / "v.safetensors", stop_threshold=0.3)
    assert PixelNavPolicy.load(w).stop_steps is None
