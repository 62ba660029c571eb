"""pmnav sim sheet: first-person views of many worlds on one contact sheet."""

import math

import numpy as np

from pmnav_bt.experiments.cli import main
from pmnav_bt.experiments.world_sheet import door_view_pose, tile
from pmnav_bt.sim.world import SimWorld


def test_the_view_pose_stands_clear_in_the_corridor_and_looks_at_a_door():
    with SimWorld("straight_office") as world:
        for seed in range(4):
            pose = door_view_pose(world, np.random.default_rng(seed))
            assert world.clearance(pose.x, pose.y, 0.17) >= 0.0
            bearings = [
                math.remainder(math.atan2(d.centre[1] - pose.y, d.centre[0] - pose.x) - pose.yaw,
                               math.tau)
                for d in world.doors.values()
                if 2.0 < math.dist(d.centre, (pose.x, pose.y)) < 5.0
            ]  # fmt: skip
            assert any(abs(b) < math.radians(30) for b in bearings)


def test_tile_lays_views_out_row_by_row():
    views = [np.full((2, 3, 3), k, np.uint8) for k in range(1, 6)]
    sheet = tile(views, 2)
    assert sheet.shape == (6, 6, 3)
    assert sheet[0, 3, 0] == 2 and sheet[2, 0, 0] == 3 and sheet[4, 0, 0] == 5
    assert sheet[4, 3, 0] == 0  # no sixth view


def test_sheet_writes_one_png_of_all_views(tmp_path, capsys):
    import cv2

    out = tmp_path / "sheet.png"
    argv = ["sim", "sheet", "--building", "straight_office", "--seeds", "2", "--out", str(out)]
    try:
        main([*argv, "--set", "sim.width=64", "--set", "sim.height=48"])
    except SystemExit as e:
        assert not e.code
    assert cv2.imread(str(out)).shape == (48, 128, 3)
    assert "2 views, world preset clean" in capsys.readouterr().out
