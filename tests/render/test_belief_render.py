"""The belief picture: drawn from a belief alone, no simulator."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from pmnav_bt.geometry import se2_apply, se2_compose
from pmnav_bt.map.generate import generate_sign_sparse
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.pose.belief import CorridorBelief
from pmnav_bt.pose.glimpse import Glimpse
from pmnav_bt.pose.visibility import Visibility, entity_xy
from pmnav_bt.render.belief import BeliefStep, hypotheses_now, render_sheet, render_step
from pmnav_bt.seams import Pose2D

ODOM_T_MAP = (3.0, -2.0, 0.7)


@pytest.fixture(scope="module")
def looked():
    """A belief after one look round in sign_sparse_1 that read the signs there, and the
    true pose."""
    pm = parse_building(generate_sign_sparse(1))
    p = next(p for p in Visibility.of(pm).lattice_points if len(p.readable) >= 2)
    truth = Pose2D(*p.xy, pm.segments[p.segment - 1].heading)
    odom = Pose2D(*se2_compose(ODOM_T_MAP, (truth.x, truth.y, truth.yaw)))
    seen = {e: tuple(se2_apply(ODOM_T_MAP, entity_xy(pm, e))) for e in p.readable}
    b = CorridorBelief(pm)
    b.observe(Glimpse(odom, seen), axis_odom=odom.yaw)
    return b, odom, truth


def test_the_likeliest_hypothesis_is_drawn_where_the_robot_is(looked):
    b, odom, truth = looked
    here, heading = hypotheses_now(b, odom)
    i = int(np.argmax(b.weights()))
    assert math.dist(here[i], (truth.x, truth.y)) < 0.5
    assert abs(math.remainder(heading[i] - truth.yaw, 2 * math.pi)) < 0.1


def test_each_step_and_the_sheet_are_written_as_pictures(looked, tmp_path):
    b, odom, truth = looked
    empty = CorridorBelief(b.pm)
    steps = [
        BeliefStep("0. nothing yet", empty, odom, truth),
        BeliefStep("1. look round", b, odom, truth),
        BeliefStep("2. fixed", b, odom, truth, fix=b.fix()[0]),
    ]
    one = cv2.imread(str(render_step(steps[1], tmp_path / "one.png")))
    sheet = cv2.imread(str(render_sheet(steps, tmp_path / "sheet.png", cols=3)))
    assert one is not None and sheet is not None
    assert sheet.shape[1] > 2 * sheet.shape[0]  # three steps side by side
    # The true pose is drawn in red, the fix in green: both on the picture.
    red = (one[:, :, 2] > 180) & (one[:, :, 1] < 80) & (one[:, :, 0] < 80)
    green = (one[:, :, 1] > 120) & (one[:, :, 0] < 90) & (one[:, :, 2] < 90)
    assert red.any() and not green.any()  # step 1 has no fix
    fixed = cv2.imread(str(render_step(steps[2], tmp_path / "fixed.png")))
    g = (fixed[:, :, 1] > 120) & (fixed[:, :, 0] < 90) & (fixed[:, :, 2] < 90)
    assert g.any()
