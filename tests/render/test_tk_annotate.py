"""'pmnav annotate' under Xvfb: real clicks and drags (xdotool), screenshots (ImageMagick)."""

from __future__ import annotations

import os
import shutil
import subprocess
import time

import cv2
import numpy as np
import pytest

from pmnav_bt.map.catalogue import load_building, resolve_building_path
from pmnav_bt.map.edit import BuildingEditor
from pmnav_bt.map.floorplan import rasterize_building, save_ros_map

NEEDED = ("Xvfb", "xdotool", "import")
missing = [t for t in NEEDED if shutil.which(t) is None]
pytestmark = pytest.mark.skipif(
    bool(missing),
    reason=f"needs {', '.join(missing)} (apt-get install xvfb xdotool imagemagick)",
)
DISPLAY = ":87"


@pytest.fixture(scope="module")
def xvfb():
    proc = subprocess.Popen(
        ["Xvfb", DISPLAY, "-screen", "0", "1400x900x24", "-nolisten", "tcp"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    env = {**os.environ, "DISPLAY": DISPLAY}
    for _ in range(50):
        if (
            subprocess.run(["xdotool", "getmouselocation"], env=env, capture_output=True).returncode
            == 0
        ):
            break
        time.sleep(0.1)
    else:
        proc.kill()
        pytest.skip("Xvfb did not start")
    old = os.environ.get("DISPLAY")
    os.environ["DISPLAY"] = DISPLAY
    yield env
    if old is None:
        os.environ.pop("DISPLAY", None)
    else:
        os.environ["DISPLAY"] = old
    proc.terminate()
    proc.wait(timeout=5)


@pytest.fixture
def app(xvfb, tmp_path):
    from pmnav_bt.render.tk_annotate import AnnotateApp

    b = load_building("l_hospital")
    save_ros_map(rasterize_building(b), tmp_path / "map.yaml")
    text = resolve_building_path("l_hospital").read_text()
    f = tmp_path / "building.yaml"
    f.write_text(text + "floor_plan: {ros_map: map.yaml}\n")
    a = AnnotateApp(BuildingEditor.open(f), size=(900, 700))
    a.root.geometry("+0+0")
    _pump(a)
    yield a
    a.root.destroy()


def _pump(app, seconds: float = 0.3) -> None:
    end = time.time() + seconds
    while time.time() < end:
        app.root.update()
        time.sleep(0.01)


def _screen(app, xy) -> tuple[int, int]:
    u, v = app.world_to_screen(xy)
    return round(app.canvas.winfo_rootx() + u), round(app.canvas.winfo_rooty() + v)


def _xdo(env, *args) -> None:
    subprocess.run(["xdotool", *map(str, args)], env=env, check=True)


def _click(app, env, xy) -> None:
    x, y = _screen(app, xy)
    _xdo(env, "mousemove", x, y)
    _pump(app, 0.1)
    _xdo(env, "click", 1)
    _pump(app)


def _shot(env, path) -> np.ndarray:
    subprocess.run(["import", "-window", "root", str(path)], env=env, check=True)
    return cv2.imread(str(path))


def test_add_a_room_by_clicking_then_undo(app, xvfb, tmp_path):
    app.mode.set("room")
    n = len(app.editor.items("rooms"))
    _click(app, xvfb, (20.0, 1.2))
    rooms = app.editor.items("rooms")
    assert len(rooms) == n + 1
    new = rooms[-1]
    assert np.allclose(new["door"], (20.0, 1.2), atol=2.5 / app.scale + 0.05)
    img = _shot(xvfb, tmp_path / "added.png")
    x, y = _screen(app, new["door"])
    patch = img[y - 2 : y + 3, x - 3 : x + 4].reshape(-1, 3).astype(int)
    brown = np.array([0x2D, 0x52, 0xA0])  # BGR of the room marker
    assert (np.abs(patch - brown).max(axis=1) < 40).any(), "no room marker where clicked"
    app.mode.set("select")
    _xdo(xvfb, "key", "ctrl+z")
    _pump(app)
    assert len(app.editor.items("rooms")) == n


def test_move_a_waypoint_by_dragging(app, xvfb):
    app.mode.set("select")
    x0, y0 = _screen(app, (42.0, 32.0))  # end1
    x1, y1 = _screen(app, (42.0, 28.0))
    _xdo(xvfb, "mousemove", x0, y0)
    _pump(app, 0.1)
    _xdo(xvfb, "mousedown", 1)
    _pump(app, 0.1)
    for k in range(1, 6):
        _xdo(xvfb, "mousemove", x0, y0 + (y1 - y0) * k // 5)
        _pump(app, 0.05)
    _xdo(xvfb, "mouseup", 1)
    _pump(app)
    x, y = app.editor.position("end1")
    assert x == pytest.approx(42.0, abs=0.3) and y == pytest.approx(28.0, abs=0.3)
    shown = list(app.messages.get(0, "end"))
    assert shown == (app.editor.problems() or ["OK: no problems, no warnings"])


def test_edit_fields_save_and_reload_equals(app, xvfb, tmp_path):
    app.mode.set("select")
    _click(app, xvfb, (6.0, 1.2))  # room1's door
    assert app.selected == "room1"
    app.fields["name"].delete(0, "end")
    app.fields["name"].insert(0, "Admissions")
    app.fields["aliases"].delete(0, "end")
    app.fields["aliases"].insert(0, "registration, front desk")
    app.apply_fields()
    _xdo(xvfb, "key", "ctrl+s")
    _pump(app)
    again = load_building(app.editor.path)
    assert again == app.editor.building()
    assert again.room("room1").aliases == ("registration", "front desk")


def test_zoom_and_pan_keep_the_point_under_the_pointer(app, xvfb):
    u, v = app.world_to_screen((21.0, 0.0))
    app.zoom(2.0, u, v)
    assert app.world_to_screen((21.0, 0.0)) == pytest.approx((u, v))
    app.pan(30, -20)
    assert app.world_to_screen((21.0, 0.0)) == pytest.approx((u + 30, v - 20))
