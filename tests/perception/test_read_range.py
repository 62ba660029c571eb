"""The reader's measured range is the one source of the tree's search distances; each
grounder declares its reading model, and one that declares none gets no PP-OCR tables."""

from __future__ import annotations

import math

import pytest

from pmnav_bt.config import load_config
from pmnav_bt.errors import ConfigError
from pmnav_bt.perception.read_range import (
    MAX_SEARCH_ANGLE_DEG,
    MIN_ABREAST_M,
    PLATE_KINDS,
    ReadingModel,
    SearchRanges,
    abreast_range,
    landmark_ranges,
    ocr_read_range,
    plate_kind,
    reading_width,
    search_settings,
    sign_ahead,
    sign_read_range,
    sign_recall,
    sign_visible_range,
)
from pmnav_bt.registry import GROUNDERS, ORACLE_READING, PP_OCR_READING, GrounderSpec
from pmnav_bt.seams import Entity


def test_the_measured_widths_read_to_the_last_reliable_band():
    # benchmarks/bench_signs.py: 94 % at 1.5-2.5 m and 49 % beyond at 320 px; 84 % at
    # 2.5-3.5 m and 30 % beyond at 640 px.
    assert ocr_read_range(320) == 2.5 and ocr_read_range(640) == 3.5
    assert ocr_read_range(320, recall=0.25) == 3.5 and ocr_read_range(640, recall=0.25) == 4.5


def test_other_widths_between_and_beyond_the_measured_ones():
    assert ocr_read_range(480) == pytest.approx(3.0)
    assert ocr_read_range(160) == pytest.approx(1.25)  # half the pixels on a sign's text
    assert ocr_read_range(1280) == 3.5  # no farther than measured: crops are upscaled anyway
    widths = [80, 160, 240, 320, 400, 640, 1920]
    ranges = [ocr_read_range(w) for w in widths]
    assert ranges == sorted(ranges)


def test_the_tree_searches_within_the_readers_range():
    # The default camera offers a 640x480 view for reading (sim.reading_width).
    ocr = search_settings(load_config(None, ["grounder.backend=ocr"]))
    assert (ocr.search_range, ocr.research_distance, ocr.read_range) == (3.0, 1.5, 3.5)
    small = search_settings(load_config(None, ["sim.reading_width=0"]))
    assert (small.search_range, small.research_distance, small.read_range) == (2.0, 1.0, 2.5)
    big = search_settings(
        load_config(None, ["sim.width=640", "sim.height=480", "sim.reading_width=0"])
    )
    assert (big.search_range, big.research_distance) == (3.0, 1.5)
    assert reading_width(load_config(None, ["sim.reading_width=480"])) == 480
    assert reading_width(load_config(None, ["sim.reading_width=200"])) == 320  # the frame's
    # The oracle reads to its max_range (9 m): the settings it was tuned with.
    oracle = load_config(None, ["grounder.backend=sim_gt"])
    assert (search_settings(oracle).search_range, search_settings(oracle).research_distance) == (
        4.5,
        2.0,
    )
    assert sign_read_range(oracle) == 9.0 and sign_visible_range(oracle) is None
    # A value set in the config wins.
    own = search_settings(load_config(None, ["tree.search_range=3.3"]))
    assert (own.search_range, own.research_distance) == (3.3, 1.65)


def test_the_localization_belief_expects_signs_where_the_reader_can_read_them(fig2_map):
    from pmnav_bt.pose.belief import CorridorBelief

    cfg = load_config(None, ["grounder.backend=ocr", "sim.reading_width=0"])
    belief = CorridorBelief(fig2_map, read_range=sign_visible_range(cfg))
    assert belief.vis.read_range == 3.5
    assert sign_visible_range(load_config(None, ["grounder.backend=ocr"])) == 6.0  # 14 % at 640
    assert CorridorBelief(fig2_map).vis.read_range == 9.5  # the oracle's
    near = belief.vis.readable_from((16.0, 0.0))
    assert near and near < CorridorBelief(fig2_map).vis.readable_from((16.0, 0.0))


def test_plate_kinds_by_the_sign_text():
    assert plate_kind("113") == plate_kind("Elevator") == "number"
    assert plate_kind("102 Pharmacy") == plate_kind("104 Laboratory") == "name"
    assert plate_kind("116 Blood Collection") == "name"  # "Blood" / "Collection"
    assert plate_kind("117 One-Stop Service Centre") == "long name"  # "Service Centre"
    assert plate_kind("Main Stairs") == plate_kind("Registration") == "long name"


def test_plates_with_a_name_are_read_from_nearer():
    # bench_signs --kind name: 42 % at 2.5-3.5 m at 640 px; --kind "long name": 74 %
    # (all plates: 84 %, bare numbers 100 %).
    assert ocr_read_range(640, kind="name") == ocr_read_range(640, kind="long name") == 2.5
    assert ocr_read_range(640, kind="number") == ocr_read_range(640) == 3.5
    assert ocr_read_range(320, kind="name") == 2.5  # the first band: 90 %
    assert ocr_read_range(640, 0.25, kind="name") == 3.5  # 10 % at 3.5-4.5 m
    cfg = load_config(None, ["grounder.backend=ocr"])
    assert search_settings(cfg, kind="name").search_range == 2.0
    assert search_settings(cfg, kind="number").search_range == 3.0
    oracle = load_config(None, ["grounder.backend=sim_gt"])
    assert search_settings(oracle, kind="name").search_range == 4.5


def test_the_built_tree_uses_them(fig2_map):
    from types import SimpleNamespace

    from pmnav_bt.testing.doubles import FakeRefiner
    from pmnav_bt.trees.pmnav import step_subtree

    def keeps(
        cfg, look_for: str, across: float | None = None, heading: float = -math.pi / 2
    ) -> dict[str, tuple[float, float]]:
        """The search distances the tree's behaviours take for a step looking for
        ``look_for``, its door ``across`` m east of the centre line (None: no door), the
        robot arriving ``heading`` (default south: the door on its left)."""
        ctx = SimpleNamespace(config=cfg, now=lambda: 0.0, refiner=FakeRefiner(), pm=fig2_map)
        root = step_subtree(ctx)
        door = None if across is None else (across, 0.0)
        target = SimpleNamespace(
            look_for=look_for, position=(0.0, 0.0), target=door, heading=heading
        )
        out = {}
        for b in root.iterate():
            if b.name in ("IntoSearchRange", "MoveOn"):
                b.get = lambda key, t=target: t if key == "target" else None
                out[b.name] = (b._metres(b.keep), b._metres(b.distance))
        return out

    ocr = load_config(None, ["grounder.backend=ocr"])
    got = keeps(ocr, "room5")  # "105"
    assert got["IntoSearchRange"][0] == 3.0 and got["MoveOn"] == (0.0, 1.5)
    got = keeps(ocr, "room17")  # "117 One-Stop Service Centre": go nearer to read it
    assert got["IntoSearchRange"][0] == 2.0 and got["MoveOn"] == (0.0, 1.0)
    got = keeps(load_config(None, ["grounder.backend=ocr", "sim.reading_width=0"]), "room5")
    assert got["IntoSearchRange"][0] == 2.0 and got["MoveOn"] == (0.0, 1.0)
    # A door 1.2 m off the centre line on the left of the way, its sign (by the building's
    # convention, on the viewer's right of it) further along: nearer still, where that
    # sign is seen within 65 deg of its plate (1.2 tan 65 - 1.14 m before the door).
    abreast = abreast_range(1.2, 1.14)
    assert abreast == pytest.approx(1.43, abs=0.01)
    assert keeps(ocr, "room5", across=1.2)["IntoSearchRange"][0] == pytest.approx(abreast)
    assert keeps(ocr, "room17", across=1.2)["IntoSearchRange"][0] == pytest.approx(abreast)
    assert keeps(ocr, "room5", across=3.0)["IntoSearchRange"][0] == 3.0  # a wide hall
    # On the right of the way its sign hangs before it: read from the plate's range.
    assert keeps(ocr, "room5", across=1.2, heading=math.pi / 2)["IntoSearchRange"][0] == 3.0
    # A building whose doors hang on the other side of their signs: the other way round.
    other = load_config(None, ["grounder.backend=ocr", "grounder.door_side=right"])
    assert keeps(other, "room5", across=1.2)["IntoSearchRange"][0] == 3.0
    north = keeps(other, "room5", across=1.2, heading=math.pi / 2)
    assert north["IntoSearchRange"][0] == pytest.approx(abreast)
    # The oracle, and a search range set in the config, keep theirs.
    oracle = load_config(None, ["grounder.backend=sim_gt"])
    assert keeps(oracle, "room5", across=1.2)["IntoSearchRange"][0] == 4.5
    own = load_config(None, ["grounder.backend=ocr", "tree.search_range=2.5"])
    assert keeps(own, "room5", across=1.2)["IntoSearchRange"][0] == 2.5


def test_a_search_reads_a_sign_beyond_its_door_from_the_abreast_range():
    """From ``abreast_range`` before level with a door, on the centre line, a sign hung
    beyond it is seen at ``MAX_SEARCH_ANGLE_DEG`` off its plate's normal (a narrow
    corridor: no nearer than ``MIN_ABREAST_M``); one hung before it, from farther."""
    across, beside = 1.5, 1.14
    d = abreast_range(across, beside)
    far = math.degrees(math.atan2(d + beside, across))
    assert far == pytest.approx(MAX_SEARCH_ANGLE_DEG)
    assert abreast_range(0.6, beside) == MIN_ABREAST_M
    assert abreast_range(across, -beside) == pytest.approx(d + 2 * beside)


def test_the_buildings_convention_says_which_side_of_its_door_a_sign_hangs():
    """``grounder.door_side`` "left" (the simulator's): facing a door, its sign is on the
    right. Passing a door on the left, its sign comes after it; on the right, before."""
    cfg = load_config(None, ["grounder.backend=ocr"])
    south = -math.pi / 2
    assert sign_ahead(cfg, south, (60.0, 5.5), (61.2, 5.5)) == 1  # east wall: on the left
    assert sign_ahead(cfg, south, (60.0, 8.5), (58.8, 8.5)) == -1  # west wall: on the right
    assert sign_ahead(cfg, math.pi / 2, (60.0, 5.5), (61.2, 5.5)) == -1  # heading north
    other = load_config(None, ["grounder.backend=ocr", "grounder.door_side=right"])
    assert sign_ahead(other, south, (60.0, 5.5), (61.2, 5.5)) == -1


# A reader that names every sign to 5 m and none beyond, whatever the camera (a test's).
FIVE_METRES = ReadingModel(
    lambda width, recall, kind: 5.0,
    lambda width, distance, kind: float(distance <= 5.0),
    lambda angle: 1.0,
    lambda width, line_height, recall: 5.0,
)


@pytest.fixture
def grounder_named():
    """Register grounder specs for one test (``grounder_named(name, **declared)``)."""
    made = []

    def register(name: str, **declared) -> object:
        GROUNDERS.register(GrounderSpec(name, "never.built:here", "", **declared))
        made.append(name)
        return load_config(None, [f"grounder.backend={name}"])

    yield register
    for name in made:
        GROUNDERS._specs.pop(name)


def test_each_grounder_reads_by_the_model_it_declares(fig2_map, grounder_named):
    ocr = load_config(None, ["grounder.backend=ocr"])
    gdino = load_config(None, ["grounder.backend=gdino_sam"])  # its signs: the same PP-OCR
    assert search_settings(gdino) == search_settings(ocr)
    assert sign_visible_range(gdino) == sign_visible_range(ocr) == 6.0
    assert sign_recall(gdino, fig2_map.building)(Entity.room("room5"), 3.0) == pytest.approx(
        sign_recall(ocr, fig2_map.building)(Entity.room("room5"), 3.0)
    )
    own = grounder_named("five", reading=f"{__name__}:FIVE_METRES")
    assert sign_read_range(own) == 5.0 and sign_visible_range(own) == 5.0
    assert search_settings(own).search_range == 4.5  # 5 - 0.5
    recall = sign_recall(own, fig2_map.building)
    assert (recall(Entity.room("room5"), 4.9), recall(Entity.room("room5"), 5.1)) == (1.0, 0.0)
    assert landmark_ranges(own) == {k: 5.0 for k in PLATE_KINDS}


def test_the_oracle_flag_is_not_the_reading_model(fig2_map, grounder_named):
    # An oracle that reads signs with PP-OCR has PP-OCR's ranges; an oracle reading model
    # reads to grounder.max_range whatever the flag says.
    flagged = grounder_named("flagged", reading=PP_OCR_READING, oracle=True)
    assert sign_read_range(flagged) == 3.5 and sign_recall(flagged, fig2_map.building)
    reads_all = grounder_named("reads_all", reading=ORACLE_READING)
    assert sign_read_range(reads_all) == 9.0 and sign_recall(reads_all, fig2_map.building) is None
    assert landmark_ranges(reads_all) is None and sign_visible_range(reads_all) is None


def test_a_grounder_that_declares_no_reading_model_gets_no_ranges(fig2_map, grounder_named):
    silent = grounder_named("silent")
    for ask in (
        sign_read_range,
        sign_visible_range,
        search_settings,
        landmark_ranges,
        lambda c: sign_recall(c, fig2_map.building),
        lambda c: SearchRanges(c, fig2_map.building),
    ):
        with pytest.raises(ConfigError, match="'silent' declares no reading model"):
            ask(silent)
