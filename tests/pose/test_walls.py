"""The corridor axis from wall points seen in depth (``pose.walls``), in a corridor with
more in view than its two walls."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pmnav_bt.pose.walls import fit_wall_line

FX, WIDTH, ROWS, WALL_H = 277.0, 320, 240, 2.5  # the simulator's 60 deg, 320 x 240 camera


def wall_pixels(segments, yaw: float) -> np.ndarray:
    """The floor-plane points (body frame) of the wall pixels a camera at the origin facing
    ``yaw`` sees, as ``walls.wall_points`` gives them: per second image column, the nearest
    surface, one point per pixel row it fills (a surface a metre off fills the frame)."""
    pts = []
    for u in range(0, WIDTH, 2):
        b = yaw + math.atan((WIDTH / 2 - u) / FX)
        d = np.array([math.cos(b), math.sin(b)])
        hits = []
        for a, c in segments:
            a, c = np.asarray(a, float), np.asarray(c, float)
            m = np.array([d, a - c]).T
            if abs(np.linalg.det(m)) > 1e-9:
                t, s = np.linalg.solve(m, a)
                if t > 0.2 and 0.0 <= s <= 1.0:
                    hits.append(t)
        if hits and (z := min(hits) * math.cos(b - yaw)) < 6.0:
            pts += [min(hits) * d] * min(ROWS // 2, int(FX * WALL_H / z / 2))
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array(pts) @ np.array([[c, -s], [s, c]])  # map -> body: turn by -yaw


def box(cx: float, cy: float, half: float, turn: float):
    c, s = math.cos(turn), math.sin(turn)
    k = [(cx + c * x - s * y, cy + s * x + c * y) for x, y in
         [(-half, -half), (half, -half), (half, half), (-half, half)]]  # fmt: skip
    return [(k[i], k[(i + 1) % 4]) for i in range(4)]


# A corridor 2.5 m wide along x, an alcove 0.65 m deep in its left wall (x 2-3.5), a
# square pillar 0.6 m wide turned 30 deg 1.6 m ahead, a cart standing at an angle.
CORRIDOR = [
    ((-5.0, 1.25), (2.0, 1.25)), ((2.0, 1.25), (2.0, 1.9)), ((2.0, 1.9), (3.5, 1.9)),
    ((3.5, 1.9), (3.5, 1.25)), ((3.5, 1.25), (9.0, 1.25)), ((-5.0, -1.25), (9.0, -1.25)),
    *box(1.6, -0.35, 0.3, math.radians(30.0)), ((1.2, 0.4), (1.6, 0.9)),
]  # fmt: skip


@pytest.mark.parametrize("yaw_deg", [0.0, 10.0, -10.0, 20.0])
def test_the_axis_is_the_walls_not_an_alcove_a_pillar_or_a_cart(yaw_deg):
    """Counted in pixels, the pillar's face and the cart fill the frame and outweigh the
    walls beyond them (the fit took a face 60 deg off); counted in floor covered, the
    walls win, and the alcove's back wall, parallel to them, agrees."""
    yaw = math.radians(yaw_deg)
    line = fit_wall_line(wall_pixels(CORRIDOR, yaw))
    assert line is not None
    assert math.degrees(line.angle) == pytest.approx(-yaw_deg, abs=1.0)


def test_a_pillar_alone_in_view_is_no_wall():
    """Facing a 0.6 m pillar from a metre off, with nothing else in view: its face fills
    the frame, but covers too little floor to be a wall."""
    assert fit_wall_line(wall_pixels(box(1.3, 0.0, 0.3, math.radians(20.0)), 0.0)) is None
