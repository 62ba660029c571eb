"""The simulated Create 3: discrete steps, velocity commands, collisions, camera, clock."""

from __future__ import annotations

import math
import threading

import numpy as np
import pytest

from pmnav_bt.backup_limit import BACKUP_LIMIT_M
from pmnav_bt.seams import (
    FORWARD_STEP_M,
    TURN_STEP_RAD,
    Base,
    Clock,
    DiscreteAction,
    MotionStatus,
    Pose2D,
    sign_label,
)
from pmnav_bt.sim.clock import SimClock
from pmnav_bt.sim.robot import MAX_ANGULAR, MAX_LINEAR, RADIUS, SimBase
from pmnav_bt.sim.world import SimWorld

A = DiscreteAction
# fig2_hospital: the corridor start-turn1 runs along x = 0 (walls at x = +-1.2); y = 8 is clear.
OPEN = Pose2D(0.0, 8.0, 0.0)


@pytest.fixture(scope="module")
def world():
    w = SimWorld("fig2_hospital")
    yield w
    w.close()


@pytest.fixture
def base(world):
    b = SimBase(world, SimClock(), pose=OPEN, width=80, height=60)
    yield b
    b.close()


def test_satisfies_the_seams(base):
    assert isinstance(base, Base)
    assert isinstance(base.clock, Clock)
    assert base.intrinsics.hfov == pytest.approx(math.radians(60.0))


def test_clock_advances_in_ticks():
    clock = SimClock(tick=0.1)
    seen = []
    clock.add_listener(seen.append)
    clock.wait(0.35)
    assert clock.now() == pytest.approx(0.35)
    assert seen == pytest.approx([0.1, 0.1, 0.1, 0.05])
    clock.wait(-1.0)
    assert clock.now() == pytest.approx(0.35)


def test_forward_step_moves_a_quarter_metre_in_the_time_the_speed_limit_implies(base):
    t0 = base.clock.now()
    base.step(A.FORWARD)
    assert base.motion_status() == MotionStatus.MOVING
    while base.motion_status() == MotionStatus.MOVING:
        base.clock.wait(base.clock.tick)
    q = base.pose()
    assert base.motion_status() == MotionStatus.IDLE
    assert (q.x, q.y, q.yaw) == pytest.approx((FORWARD_STEP_M, 8.0, 0.0), abs=1e-9)
    implied = FORWARD_STEP_M / MAX_LINEAR
    assert base.step_duration(A.FORWARD) == pytest.approx(implied)
    assert implied <= base.clock.now() - t0 < implied + base.clock.tick + 1e-9
    assert base.stats.path_length == pytest.approx(FORWARD_STEP_M)
    assert base.stats.actions == 1


@pytest.mark.parametrize("action,sign", [(A.TURN_LEFT, 1), (A.TURN_RIGHT, -1)])
def test_turn_step_turns_thirty_degrees(base, action, sign):
    t0 = base.clock.now()
    assert base.execute(action) == MotionStatus.IDLE
    q = base.pose()
    assert q.yaw == pytest.approx(sign * TURN_STEP_RAD, abs=1e-9)
    assert (q.x, q.y) == (OPEN.x, OPEN.y)
    implied = TURN_STEP_RAD / MAX_ANGULAR
    assert implied <= base.clock.now() - t0 < implied + base.clock.tick + 1e-9
    assert base.stats.rotation == pytest.approx(TURN_STEP_RAD)


def test_driving_into_a_wall_stops_at_the_wall_with_one_collision(base):
    statuses = [base.execute(A.FORWARD) for _ in range(8)]  # 2 m towards a wall 1.2 m away
    assert statuses[:4] == [MotionStatus.IDLE] * 4
    assert statuses[4:] == [MotionStatus.BLOCKED] * 4
    gap = 1.2 - base.pose().x  # centre to wall surface
    assert RADIUS - 1e-6 <= gap <= RADIUS + 1e-3
    assert base.stats.collisions == 1
    assert base.stats.actions == 8
    assert base.stats.path_length == pytest.approx(1.2 - RADIUS, abs=1e-3)
    # Backing off (as far as the backup buffer allows) and driving in again is a second
    # collision event.
    base.set_velocity(-0.2, 0.0)
    base.clock.wait(1.0)
    assert base.pose().x == pytest.approx(1.2 - RADIUS - BACKUP_LIMIT_M, abs=2e-3)
    assert base.motion_status() == MotionStatus.BLOCKED
    base.set_velocity(1.0, 0.0)
    base.clock.wait(3.0)
    assert base.motion_status() == MotionStatus.BLOCKED
    assert base.velocity_command == (0.0, 0.0)
    assert RADIUS - 1e-6 <= 1.2 - base.pose().x <= RADIUS + 1e-3
    assert base.stats.collisions == 2


def test_velocity_commands_are_clipped(base):
    base.set_velocity(5.0, -7.0)
    assert base.velocity_command == (MAX_LINEAR, -MAX_ANGULAR)
    base.set_velocity(0.0, 9.0)
    assert base.motion_status() == MotionStatus.MOVING
    base.clock.wait(0.5)
    assert base.pose().yaw == pytest.approx(0.5 * MAX_ANGULAR, abs=1e-9)
    base.set_pose(Pose2D(0.0, 8.0, -math.pi / 2))  # along the corridor
    base.set_velocity(3.0, 0.0)
    base.clock.wait(2.0)
    assert base.pose().y == pytest.approx(8.0 - 2.0 * MAX_LINEAR, abs=1e-9)
    base.set_velocity(0.0, 0.0)
    assert base.motion_status() == MotionStatus.IDLE


def test_arc_integration_follows_a_circle(base):
    base.set_pose(Pose2D(0.0, 8.0, math.pi / 2))
    v, w = 0.2, 0.4
    base.set_velocity(v, w)
    base.clock.wait(1.0)
    q = base.pose()
    r = v / w  # centre of the circle at (-r, 8)
    assert math.hypot(q.x + r, q.y - 8.0) == pytest.approx(r, abs=1e-4)
    assert q.yaw == pytest.approx(math.pi / 2 + w, abs=1e-9)


def test_obstacles_block(world, base):
    base.set_pose(Pose2D(0.0, 8.0, math.pi / 2))
    body = world.add_obstacle(0.0, 9.0, 0.4)
    try:
        for _ in range(6):
            base.execute(A.FORWARD)
        assert base.motion_status() == MotionStatus.BLOCKED
        assert base.pose().y == pytest.approx(9.0 - 0.2 - RADIUS, abs=1e-3)
        assert base.stats.collisions == 1
    finally:
        world.remove_obstacle(body)
    assert base.execute(A.FORWARD) == MotionStatus.IDLE


def test_stop_drops_the_step_and_stop_action_counts(base):
    base.step(A.FORWARD)
    base.clock.wait(0.3)
    base.stop()
    x = base.pose().x
    base.clock.wait(1.0)
    assert base.pose().x == x == pytest.approx(0.3 * MAX_LINEAR, abs=base.clock.tick * MAX_LINEAR)
    assert base.motion_status() == MotionStatus.IDLE
    assert base.execute(A.STOP) == MotionStatus.IDLE
    assert base.stats.actions == 2


def test_teleport_is_not_driving(base):
    base.set_pose(Pose2D(0.0, 20.0, 7.0))
    q = base.pose()
    assert (q.x, q.y) == (0.0, 20.0) and q.yaw == pytest.approx(7.0 - 2 * math.pi)
    assert base.stats.path_length == 0.0


def test_observation(base):
    base.clock.wait(0.5)
    obs = base.observe()
    assert obs.rgb.shape == (60, 80, 3) and obs.rgb.dtype == np.uint8
    assert obs.depth.shape == (60, 80) and obs.depth.dtype == np.float32
    assert obs.segmentation.shape == (60, 80) and obs.segmentation.dtype == np.int32
    assert obs.stamp == base.clock.now() == pytest.approx(0.5)
    assert obs.pose == base.pose()
    assert obs.camera_height == 1.6
    assert {obs.labels[int(i)] for i in np.unique(obs.segmentation)} == {"wall"}
    assert obs.depth[30, 40] == pytest.approx(1.2, abs=0.03)  # facing the wall at x = 1.2


def test_view_facing_a_sign_segments_the_sign(world, base):
    for room in ("room1", "room4", "room17"):
        base.set_pose(world.signs[room].viewpoint(1.5))
        obs = base.observe()
        assert sign_label(room) in {obs.labels[int(i)] for i in np.unique(obs.segmentation)}


def test_view_at_a_yaw_offset_equals_a_turned_body(base):
    turned = base.render_view(math.pi / 2)
    base.set_pose(Pose2D(OPEN.x, OPEN.y, math.pi / 2))
    direct = base.observe()
    assert turned.pose == OPEN
    assert np.array_equal(turned.rgb, direct.rgb)
    assert np.array_equal(turned.segmentation, direct.segmentation)


def test_rendering_in_a_worker_while_the_clock_runs(base):
    base.set_pose(Pose2D(0.0, 8.0, -math.pi / 2))
    frames, errors = [], []

    def worker():
        try:
            for k in range(12):
                frames.append(base.render_view(k * math.pi / 6))
        except Exception as err:  # pragma: no cover - the failure we test for
            errors.append(err)

    t = threading.Thread(target=worker)
    t.start()
    for _ in range(8):
        base.execute(A.FORWARD)
    t.join(timeout=30)
    assert not errors and len(frames) == 12
    assert base.pose().y == pytest.approx(8.0 - 8 * FORWARD_STEP_M, abs=1e-9)


def test_it_reverses_only_within_the_create3_backup_buffer(base):
    """As the Create 3 with safety_override none: no reverse until it has driven forward,
    then at most 0.15 m; a reverse beyond that stops BLOCKED, without a collision."""
    base.set_pose(Pose2D(0.0, 8.0, math.pi / 2))
    base.set_velocity(-0.2, 0.0)
    assert base.motion_status() == MotionStatus.BLOCKED  # refused: nothing driven yet
    base.clock.wait(0.5)
    assert base.pose().y == pytest.approx(8.0)
    base.set_velocity(0.2, 0.0)
    base.clock.wait(2.0)  # 0.4 m forward fills the buffer (capped)
    y = base.pose().y
    base.set_velocity(-0.2, 0.0)
    base.clock.wait(2.0)
    assert base.pose().y == pytest.approx(y - BACKUP_LIMIT_M, abs=1e-6)
    assert base.motion_status() == MotionStatus.BLOCKED
    assert base.velocity_command == (0.0, 0.0)
    assert base.stats.collisions == 0
    base.set_velocity(0.2, 0.0)  # 0.1 m forward: 0.1 m of reverse again
    base.clock.wait(0.5)
    y = base.pose().y
    base.set_velocity(-0.2, 0.0)
    base.clock.wait(2.0)
    assert base.pose().y == pytest.approx(y - 0.1, abs=1e-6)


def test_the_configs_robot_drives_on_drifting_odometry_unless_the_noise_is_zero(world):
    from pmnav_bt.config import load_config
    from pmnav_bt.sim.odometry import NoisyOdometry, simulated_robot

    sim = load_config(None, ["sim.width=64", "sim.height=48", "sim.reading_width=0"]).sim
    body, base = simulated_robot(world, sim, OPEN, seed=3)
    try:
        assert isinstance(base, NoisyOdometry) and base.inner is body
        assert (body.intrinsics.width, body.intrinsics.height) == (64, 48)
        assert base.noise == sim.odometry_noise > 0
    finally:
        body.close()
    exact = load_config(None, ["sim.width=64", "sim.height=48", "sim.odometry_noise=0"]).sim
    body, base = simulated_robot(world, exact, OPEN, seed=3)
    try:
        assert base is body
    finally:
        body.close()
