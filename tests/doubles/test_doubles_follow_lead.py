"""The localization drive's decisions on the test doubles (no pybullet): the leaves of
``trees.localize.follow_lead_subtree`` ticked on a FakeBase, with the wall looks scripted
(what depth and the signs would show) and a scripted belief (its lead, its lead worked out
again, what it is told). A status is asserted per tick where the tick matters."""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass, field, replace

import pytest
from py_trees.common import Status

from pmnav_bt.behaviours import follow_lead
from pmnav_bt.behaviours.belief import DriveEnd
from pmnav_bt.behaviours.follow_lead import BACK_OFF_S, SLIDE_ACROSS_M, WallLook
from pmnav_bt.behaviours.recovery import BACKUP_LIMIT_M, BACKUP_TIME_S, BackUp
from pmnav_bt.contact import BACK_OFF_SPEED as BACKUP_SPEED
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.seams import Pose2D
from pmnav_bt.trees.localize import follow_lead_subtree


@pytest.fixture(scope="module")
def building():
    return load_building("straight_office")


EAST = Pose2D(4.0, 0.0, 0.0)  # straight_office: the corridor runs east along y = 0
PERIOD = 0.1  # clock seconds a tick (as the rig's run)


@dataclass
class Lead:
    heading: float
    distance: float
    support: float = 0.8


@dataclass
class ScriptedBelief:
    """The belief as the drive sees it: a lead, the lead worked out again (``turned``:
    None keeps to the way), and what the drive tells it."""

    lead_: Lead | None
    turned: Lead | None = None
    pending_blocked: float | None = None
    asked_again: list[tuple[float, float]] = field(default_factory=list)  # (x, heading)
    rays: list[float] = field(default_factory=list)

    def lead(self, pose, most):
        return self.lead_

    def turned_lead(self, pose, heading, most):
        self.asked_again.append((pose.x, heading))
        return self.turned

    threads: list[str] = field(default_factory=list)  # where each ray was weighed

    def fork(self):
        return self  # one double: what the drive tells it is recorded in one place

    def observe_ray(self, seen_from, free, axis, doors):
        self.rays.append(seen_from.x)
        self.threads.append(threading.current_thread().name)

    def rescale_due(self, gain):
        return False


class Looks:
    """Scripted wall looks: ``script(pose, n)`` says what the n-th look (from 0) sees."""

    def __init__(self, script):
        self.script, self.n = script, 0

    def __call__(self, ctx) -> WallLook:
        pose = ctx.base.pose()
        got = self.script(pose, self.n)
        self.n += 1
        return got


def look(pose, *, free=None, signs=(), beside=None) -> WallLook:
    """A look from ``pose``: no walls fitted, ``free`` floor ahead, signs ``signs`` m ahead."""
    return WallLook(pose, None, None, list(signs), free, beside, None)


def plain(pose, n) -> WallLook:
    return look(pose, free=20.0)


def rig_with(make_rig, monkeypatch, script=plain, belief=None):
    r = make_rig(EAST)
    monkeypatch.setattr(follow_lead, "look_at_walls", Looks(script))
    r.set(belief=belief, views=[])
    return r


def tick(r, tree) -> tuple[Status, str, tuple[float, float]]:
    """One tick as the runner does it: (status, the running leaf, velocity command)."""
    tree.tick_once()
    tip = tree.tip()
    r.ctx.worker.drain()
    cmd = r.base.velocity_command
    r.base.clock.wait(PERIOD)
    return tree.status, tip.name if tip is not None else "", cmd


def run(r, tree, max_ticks=2000) -> list[tuple[Status, str, tuple[float, float]]]:
    seen = []
    for _ in range(max_ticks):
        seen.append(tick(r, tree))
        if seen[-1][0] != Status.RUNNING:
            return seen
    raise AssertionError("the drive did not end")


def leaves(seen) -> list[str]:
    """The leaves that ran on, in order, each once per stretch (the last tick's tip is
    the subtree's last child)."""
    out = []
    for _, name, _ in seen[:-1]:
        if not out or out[-1] != name:
            out.append(name)
    return out


def test_without_a_belief_the_drive_covers_two_metres_towards_the_most_open_view(
    make_rig, monkeypatch
):
    r = rig_with(make_rig, monkeypatch)
    tree = follow_lead_subtree(r.ctx, max_distance=4.0)
    seen = run(r, tree)
    assert seen[-1][0] == Status.SUCCESS
    assert r.get("drive_end") == DriveEnd.COVERED
    assert r.base.pose().x - EAST.x == pytest.approx(2.0, abs=0.05)
    assert r.base.velocity_command == (0.0, 0.0)
    assert leaves(seen) == ["LocalizeAlign", "LocalizeDrive"]


def test_the_lead_is_chosen_in_the_worker_and_the_drive_turns_onto_it_at_once(
    make_rig, monkeypatch
):
    belief = ScriptedBelief(Lead(heading=math.pi / 2, distance=1.0))
    r = rig_with(make_rig, monkeypatch, belief=belief)
    tree = follow_lead_subtree(r.ctx, max_distance=4.0)
    status, leaf, cmd = tick(r, tree)  # the lead is worked out between ticks
    assert (status, leaf, cmd) == (Status.RUNNING, "LocalizeChooseLead", (0.0, 0.0))
    status, leaf, cmd = tick(r, tree)  # it came: turning onto it in the same tick
    assert (status, leaf) == (Status.RUNNING, "LocalizeAlign") and cmd[1] > 0.0
    run(r, tree)
    assert r.get("drive_end") == DriveEnd.COVERED
    p = r.base.pose()
    assert p.y == pytest.approx(1.0, abs=0.05) and p.x == pytest.approx(EAST.x, abs=0.05)


def test_a_sign_read_ahead_cuts_the_distance_short(make_rig, monkeypatch):
    """A sign 3.5 m ahead in the first look: the drive stops 2.5 m short of it, 1 m on,
    and says why (the next look round is not skipped)."""
    belief = ScriptedBelief(Lead(heading=0.0, distance=6.0))
    r = rig_with(make_rig, monkeypatch, lambda p, n: look(p, free=20.0, signs=(3.5,)), belief)
    seen = run(r, follow_lead_subtree(r.ctx, max_distance=8.0))
    assert seen[-1][0] == Status.SUCCESS
    assert r.get("drive_end") == DriveEnd.SIGN
    assert r.base.pose().x - EAST.x == pytest.approx(1.0, abs=0.05)


def test_a_wall_ahead_ends_the_drive_and_notes_the_way_blocked(make_rig, monkeypatch):
    """Depth shows a wall 0.6 m ahead 2 m into the drive: stop in that tick, SUCCESS
    (a tick later when that look's ray is being weighed in the worker), and the belief
    notes the drive's heading blocked."""
    belief = ScriptedBelief(Lead(heading=0.0, distance=6.0))

    def wall_at_6(p, n):
        return look(p, free=0.6 if p.x >= 6.0 else 20.0)

    r = rig_with(make_rig, monkeypatch, wall_at_6, belief)
    seen = run(r, follow_lead_subtree(r.ctx, max_distance=8.0))
    assert (seen[-1][0], seen[-1][2]) == (Status.SUCCESS, (0.0, 0.0))
    drove = max(i for i, x in enumerate(seen) if x[2][0] > 0.0)  # driving until then
    assert seen[drove][1] == "LocalizeDrive" and seen[drove + 1][2] == (0.0, 0.0)
    assert len(seen) - 1 - (drove + 1) <= 1  # at rest for at most the ray's tick
    assert r.get("drive_end") == DriveEnd.WALL
    assert belief.rays[-1] >= 6.0  # the view at the wall was told
    assert belief.pending_blocked == pytest.approx(0.0)
    assert 6.0 <= r.base.pose().x < 7.2  # a wall look a second


def test_a_blocked_drive_rests_a_tick_then_backs_off_the_wall(make_rig, monkeypatch):
    """The body blocked 1 m into the drive: the drive stops it (a tick at rest), notes the
    way blocked, and the BackUp recovery reverses BACKUP_LIMIT_M off the wall."""
    belief = ScriptedBelief(Lead(heading=0.0, distance=6.0))
    r = rig_with(make_rig, monkeypatch, belief=belief)
    tree = follow_lead_subtree(r.ctx, max_distance=8.0)
    while r.base.pose().x < EAST.x + 1.0:
        assert tick(r, tree)[0] == Status.RUNNING
    r.base.blocked = True
    assert tick(r, tree) == (Status.RUNNING, "LocalizeDrive", (0.0, 0.0))  # stopped
    assert belief.pending_blocked == pytest.approx(0.0)
    assert r.get("drive_end") == DriveEnd.BLOCKED
    r.base.blocked = False  # the wall is in front: reversing is free
    blocked_at = r.base.pose().x
    assert tick(r, tree) == (Status.RUNNING, "LocalizeBackUp", (-BACKUP_SPEED, 0.0))
    seen = run(r, tree)
    assert seen[-1][:2] == (Status.SUCCESS, "LocalizeBackUp")
    assert blocked_at - r.base.pose().x == pytest.approx(BACKUP_LIMIT_M, abs=0.02)
    assert r.get("drive_end") == DriveEnd.BLOCKED


def test_a_drive_refused_at_once_backs_up_only_as_far_as_the_body_lets_it(make_rig, monkeypatch):
    """Blocked before it moved 0.2 m: a brush with a wall, not the corridor's end (the
    belief is not told); BackUp gives up when the body refuses to reverse."""
    belief = ScriptedBelief(Lead(heading=0.0, distance=6.0))
    r = rig_with(make_rig, monkeypatch, belief=belief)
    r.base.blocked = True
    seen = run(r, follow_lead_subtree(r.ctx, max_distance=8.0), max_ticks=20)
    assert [s[1] for s in seen][-4:] == [
        "LocalizeDrive",  # driving
        "LocalizeDrive",  # blocked: stopped
        "LocalizeBackUp",  # reversing
        "LocalizeBackUp",  # refused
    ]
    assert seen[-2][2] == (-BACKUP_SPEED, 0.0) and seen[-1][0] == Status.SUCCESS
    assert belief.pending_blocked is None
    assert r.get("drive_end") == DriveEnd.BLOCKED


@pytest.mark.parametrize("timeout_s", [BACK_OFF_S, BACKUP_TIME_S])
def test_a_backup_that_does_not_move_gives_up_after_its_timeout(make_rig, timeout_s):
    """The drive's backing off gives up sooner than the recoveries' (its own timeout)."""
    r = make_rig(EAST)
    r.base.max_linear = 0.0  # the body takes the command but does not move
    backup = BackUp("BackUp", r.ctx, timeout_s=timeout_s)
    seen = r.run(backup)
    assert seen[-1] == Status.SUCCESS and "out of time" in backup.feedback_message
    assert len(seen) == pytest.approx(timeout_s / PERIOD + 1, abs=1)


def test_a_corner_early_in_the_drive_is_slid_past_and_the_drive_goes_on(make_rig, monkeypatch):
    """The first look shows a wall 0.6 m ahead with open floor 40 deg to the left: the
    drive stops (a tick at rest), slides left until SLIDE_ACROSS_M across its heading,
    faces its heading, looks at the walls again and covers the rest of its distance."""
    belief = ScriptedBelief(Lead(heading=0.0, distance=3.0))

    def corner_first(p, n):
        if n == 0:
            return look(p, free=0.6, beside=math.radians(40.0))
        return look(p, free=20.0)

    r = rig_with(make_rig, monkeypatch, corner_first, belief)
    seen = run(r, follow_lead_subtree(r.ctx, max_distance=4.0))
    assert leaves(seen) == [
        "LocalizeChooseLead",
        "LocalizeAlign",
        "LocalizeDrive",
        "LocalizeSlidePastCorner",
        "LocalizeAlignAgain",
        "LocalizeDriveOn",
    ]
    first_drive = next(i for i, s in enumerate(seen) if s[1] == "LocalizeDrive")
    assert seen[first_drive][2] == (0.0, 0.0)  # stopped at the corner, a tick at rest
    assert seen[first_drive + 1][1] == "LocalizeSlidePastCorner"
    assert seen[-1][0] == Status.SUCCESS and r.get("drive_end") == DriveEnd.COVERED
    p = r.base.pose()
    assert p.y == pytest.approx(SLIDE_ACROSS_M, abs=0.05)  # slid left, then on east
    assert math.hypot(p.x - EAST.x, p.y) == pytest.approx(3.0, abs=0.05)


def test_a_second_corner_in_one_drive_is_a_wall(make_rig, monkeypatch):
    """One slide a drive: a wall ahead again after it ends the drive."""
    belief = ScriptedBelief(Lead(heading=0.0, distance=3.0))
    r = rig_with(
        make_rig, monkeypatch, lambda p, n: look(p, free=0.6, beside=math.radians(40.0)), belief
    )
    seen = run(r, follow_lead_subtree(r.ctx, max_distance=4.0))
    # the drive on ends in the tick it starts: the wall again
    assert leaves(seen)[-2:] == ["LocalizeSlidePastCorner", "LocalizeAlignAgain"]
    assert r.get("drive_end") == DriveEnd.WALL
    assert belief.pending_blocked == pytest.approx(0.0)


@pytest.mark.parametrize("another_way", [True, False])
def test_the_lead_is_worked_out_again_every_three_metres(make_rig, monkeypatch, another_way):
    """3 m into a 6 m drive the lead is worked out again (worker) along the drive's
    heading; when it now goes another way the drive stops in the tick the answer comes
    (``rethought``: look again from here), else it drives on."""
    turned = Lead(heading=math.pi, distance=2.0) if another_way else None
    belief = ScriptedBelief(Lead(heading=0.0, distance=6.0), turned=turned)
    r = rig_with(make_rig, monkeypatch, belief=belief)
    seen = run(r, follow_lead_subtree(r.ctx, max_distance=8.0))
    assert len(belief.asked_again) >= 1
    x, heading = belief.asked_again[0]
    assert x - EAST.x == pytest.approx(3.0, abs=0.05) and heading == pytest.approx(0.0)
    assert seen[-1][2] == (0.0, 0.0)
    if another_way:
        assert r.get("drive_end") == DriveEnd.RETHOUGHT
        assert r.base.pose().x - EAST.x == pytest.approx(3.0, abs=0.1)
    else:
        assert r.get("drive_end") == DriveEnd.COVERED
        assert r.base.pose().x - EAST.x == pytest.approx(6.0, abs=0.05)


def test_the_drive_tells_the_belief_the_floor_ahead_every_metre(make_rig, monkeypatch):
    belief = ScriptedBelief(Lead(heading=0.0, distance=4.5))
    r = rig_with(make_rig, monkeypatch, belief=belief)
    run(r, follow_lead_subtree(r.ctx, max_distance=8.0))
    steps = [b - a for a, b in zip([EAST.x, *belief.rays], belief.rays, strict=False)]
    assert len(belief.rays) >= 3 and all(s >= 1.0 for s in steps), belief.rays


def test_an_interrupted_drive_stops_the_body(make_rig, monkeypatch):
    r = rig_with(make_rig, monkeypatch, belief=ScriptedBelief(Lead(heading=0.0, distance=6.0)))
    tree = follow_lead_subtree(r.ctx, max_distance=8.0)
    for _ in range(10):
        tick(r, tree)
    assert r.base.velocity_command[0] > 0.0
    tree.stop(Status.INVALID)
    assert r.base.velocity_command == (0.0, 0.0)


def test_the_drive_weighs_its_rays_in_the_worker(make_rig, monkeypatch):
    """Weighing every hypothesis with a ray takes 10-20 ms: never in a tick."""
    belief = ScriptedBelief(Lead(heading=0.0, distance=4.5))
    r = rig_with(make_rig, monkeypatch, belief=belief)
    run(r, follow_lead_subtree(r.ctx, max_distance=8.0))
    assert belief.threads and all(t.startswith("pmnav-worker") for t in belief.threads)


@dataclass
class ForkingBelief(ScriptedBelief):
    """A belief the drive forks to weigh a ray on, as the real one (each fork its own rays)."""

    def fork(self):
        return replace(self, rays=list(self.rays), threads=list(self.threads))


def test_a_ray_from_the_look_that_ends_the_drive_is_in_the_belief_after_it(make_rig, monkeypatch):
    """The look that shows the wall ahead also tells the belief the floor ahead: the drive
    ends when that ray is weighed in (a tick at rest), and the belief the next look reads
    has it, with the way noted blocked."""
    monkeypatch.setattr(follow_lead, "RAY_SPACING_M", 0.0)  # a ray from every look
    belief = ForkingBelief(Lead(heading=0.0, distance=6.0))

    def wall_at_6(p, n):
        return look(p, free=0.6 if p.x >= 6.0 else 20.0)

    r = rig_with(make_rig, monkeypatch, wall_at_6, belief)
    seen = run(r, follow_lead_subtree(r.ctx, max_distance=8.0))
    assert seen[-2][1:] == ("LocalizeDrive", (0.0, 0.0))  # stopped, waiting for the ray
    assert r.get("drive_end") == DriveEnd.WALL
    after = r.get("belief")
    assert after is not belief and belief.rays == []  # weighed on forks, not in place
    assert after.rays[-1] >= 6.0 and after.pending_blocked == pytest.approx(0.0)
