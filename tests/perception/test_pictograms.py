"""The pictogram reader: a toilet plate is read as the map's toilets, a text plate is not a
pictogram, and a read short of the calibrated confidence is no sighting."""

from __future__ import annotations

import math
from dataclasses import replace

import cv2
import numpy as np
import pytest

from pmnav_bt.map.building import Building
from pmnav_bt.map.signage import PlateStyle
from pmnav_bt.perception.pictograms import CLASSES, PictogramReader
from pmnav_bt.perception.sign_match import SignMatcher, decide
from pmnav_bt.seams import CameraIntrinsics, Entity, Observation, Pose2D
from pmnav_bt.sim.scene.plates import make_plate
from pmnav_bt.sim.textures import make_sign

K = CameraIntrinsics.from_hfov(320, 240, math.radians(60.0))  # the tree's frame
WALL_RGB = (200, 196, 180)

TOILET_STYLE = PlateStyle(
    plate_width=0.3,
    cap_height=0.04,
    font="dejavu_sans",
    text_rgb=(255, 255, 255),
    plate_rgb=(22, 52, 112),
    mounting="beside",
    layout="number_and_name",
    height=1.6,
    pictogram="toilet",
)


def plate_frame(image: np.ndarray, width_m: float, height_m: float, range_m: float):
    """A camera facing a plain wall ``range_m`` away with one plate texture at its centre."""
    rgb = np.full((K.height, K.width, 3), WALL_RGB, np.uint8)
    px_per_m = K.fx / range_m
    w, h = int(round(width_m * px_per_m)), int(round(height_m * px_per_m))
    u0, v0 = int(round(K.cx - w / 2)), int(round(K.cy - h / 2))
    rgb[v0 : v0 + h, u0 : u0 + w] = cv2.resize(image, (w, h), interpolation=cv2.INTER_AREA)
    depth = np.full((K.height, K.width), range_m, np.float32)
    return Observation(rgb, Pose2D(0.0, 0.0, 0.0), 0.0, K, depth=depth, camera_height=1.6)


def toilet_frame(range_m: float = 1.2) -> Observation:
    tex = make_plate("", TOILET_STYLE)
    return plate_frame(tex.image, tex.width_m, tex.height_m, range_m)


def with_toilets(b: Building, *ids: str) -> Building:
    """``b`` with the rooms ``ids`` made toilets by the file's ``amenity`` field."""
    rooms = tuple(
        r.model_copy(update={"amenity": "toilet"}) if r.id in ids else r for r in b.rooms
    )
    return b.model_copy(update={"rooms": rooms})


@pytest.fixture(scope="module")
def reader():
    return PictogramReader()


def test_a_rendered_toilet_plate_is_read_as_a_toilet(reader):
    obs = toilet_frame()
    from pmnav_bt.perception.signs import SignReader

    pytest.importorskip("rapidocr_onnxruntime")
    found = [b for b, _ in SignReader().candidates(obs.rgb)]
    assert found, "the candidate finder proposes the plate"
    reads = reader.read(obs.rgb, found)
    best = max(reads, key=lambda r: r.probs[CLASSES.index("toilet")])
    assert best.kind == "toilet" and best.sighting and best.p >= reader.sighting_p


@pytest.mark.parametrize("text", ["102 Pharmacy", "113", "117 One-Stop Service Centre"])
@pytest.mark.parametrize("styled", [False, True], ids=["historical plate", "toilets' style"])
def test_a_text_plate_is_not_read_as_a_pictogram(reader, text, styled):
    # the historical plate, or a room plate in the very style of the toilet plates
    tex = make_plate(text, replace(TOILET_STYLE, pictogram=None)) if styled else make_sign(text)
    obs = plate_frame(tex.image, tex.width_m, tex.height_m, 2.0)
    from pmnav_bt.perception.signs import SignReader

    pytest.importorskip("rapidocr_onnxruntime")
    found = [b for b, _ in SignReader().candidates(obs.rgb)]
    assert found
    assert not any(r.sighting for r in reader.read(obs.rgb, found))


def test_a_read_short_of_the_calibrated_confidence_is_not_a_sighting(reader):
    t = CLASSES.index("toilet")
    sure = np.zeros(len(CLASSES))
    sure[t] = reader.sighting_p
    sure[CLASSES.index("text")] = 1.0 - reader.sighting_p
    assert reader.decide((0, 0, 10, 10), sure).sighting
    unsure = sure.copy()
    unsure[t] = reader.sighting_p - 0.01
    unsure[CLASSES.index("text")] = 1.0 - unsure[t]
    read = reader.decide((0, 0, 10, 10), unsure)
    assert not read.sighting and read.ambiguous and read.kind == "toilet"
    text = np.zeros(len(CLASSES))
    text[CLASSES.index("text")] = 0.9
    text[t] = 0.1
    read = reader.decide((0, 0, 10, 10), text)
    assert not read.sighting and not read.ambiguous and read.kind == "text"


def test_the_grounder_names_the_maps_toilet_from_its_pictogram(fig2):
    pytest.importorskip("rapidocr_onnxruntime")
    from pmnav_bt.perception.grounders.ocr import OcrGrounder

    b = with_toilets(fig2, "room13")
    dets = OcrGrounder(b, pictograms=PictogramReader()).read_signs(toilet_frame())
    assert [d.entity for d in dets] == [Entity.room("room13")]
    assert dets[0].label == "[toilet]"
    # Without the reader, the plate names nothing; with no toilet in the map, neither.
    assert OcrGrounder(b).read_signs(toilet_frame()) == []
    assert OcrGrounder(fig2, pictograms=PictogramReader()).read_signs(toilet_frame()) == []


def test_an_unsure_pictogram_read_is_no_sighting_but_a_plate_to_read_again(fig2):
    pytest.importorskip("rapidocr_onnxruntime")
    from pmnav_bt.perception.grounders.ocr import OcrGrounder

    b = with_toilets(fig2, "room13")
    strict = PictogramReader(sighting_p=1.01)  # no read is ever that sure
    g = OcrGrounder(b, pictograms=strict)
    obs = toilet_frame()
    assert g.read_signs(obs) == []
    assert len(g.unread_plates(since=0.0)) == 1


def test_a_pictogram_names_the_one_toilet_and_not_one_of_two(fig2):
    one = SignMatcher(with_toilets(fig2, "room13"))
    m = decide(one.pictogram_evidence("toilet"))
    assert m is not None and m.entity == Entity.room("room13")
    two = SignMatcher(with_toilets(fig2, "room13", "room5"))
    assert decide(two.pictogram_evidence("toilet")) is None
    assert decide(SignMatcher(fig2).pictogram_evidence("toilet")) is None


def test_the_numpy_network_is_the_torch_one():
    torch = pytest.importorskip("torch")
    from pmnav_bt.experiments.pictogram_train import network
    from pmnav_bt.perception.pictograms import INPUT_H, INPUT_W, forward

    torch.manual_seed(0)
    net = network()
    x = np.random.default_rng(0).normal(size=(3, 1, INPUT_H, INPUT_W)).astype(np.float32)
    params = {k: v.detach().numpy() for k, v in net.state_dict().items()}
    with torch.no_grad():
        want = net(torch.from_numpy(x)).numpy()
    assert np.allclose(forward(params, x), want, atol=1e-4)


def test_a_missing_weights_file_is_one_clear_error(tmp_path):
    from pmnav_bt.errors import BackendError

    with pytest.raises(BackendError, match="pictogram weights not found"):
        PictogramReader(tmp_path / "none.safetensors")
