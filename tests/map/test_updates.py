"""The map-updates file: written as a run sees disagreements, read back, refused when bad,
and reviewed with ``pmnav map updates`` (listed, one entry applied to a copy of a building)."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from pmnav_bt.cli import main
from pmnav_bt.map.catalogue import load_building, resolve_building_path
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.map.updates import (
    Evidence,
    MapUpdate,
    MapUpdatesError,
    UpdatesFile,
    corridor_blocked,
    load_updates,
)
from pmnav_bt.seams import Pose2D


def _pmnav(*args: str) -> int:
    with pytest.raises(SystemExit) as ex:
        main(list(args))
    return ex.value.code


def _renamed(subject="room8", seen="108 Quiet Room") -> MapUpdate:
    ev = Evidence(12.5, (1.0, 2.0, 0.5), (36.1, 9.0, 1.57), (seen, seen))
    return MapUpdate("sign_text", "room", subject, "108", seen, (36.9, 10.0), ev)


def _moved() -> MapUpdate:
    ev = Evidence(20.0, (0.0, 0.0, 0.0), (37.0, 8.0, 1.57), ("Elevator", "Elevator"))
    return MapUpdate("moved", "landmark", "elevator1", "(37.4, 6.0)", "(37.4, 10.2)",
                     (37.4, 10.2), ev)  # fmt: skip


def _write(tmp_path, updates, building="fig2_hospital"):
    f = UpdatesFile(tmp_path / "ep.map_updates.jsonl", building)
    for u in updates:
        f.record(u, np.full((20, 40, 3), 200, np.uint8))
    return f.path


def test_what_is_written_is_read_back_with_its_crop(tmp_path):
    pm = parse_building(load_building("fig2_hospital"))
    blocked = corridor_blocked(
        pm, 3, 30.0, Pose2D(1, 2, 0), None, "BLOCKED: obstacle 0.8 m ahead"
    )
    path = _write(tmp_path, [_renamed(), blocked])
    log = load_updates(path)
    assert log.building == "fig2_hospital"
    assert [u.kind for u in log.updates] == ["sign_text", "corridor_blocked"]
    assert log.updates[0].seen == "108 Quiet Room" and log.updates[0].at == (36.9, 10.0)
    assert log.updates[1].subject == "seg3" and log.updates[1].evidence.pose is None
    crop = path.parent / log.updates[0].evidence.crop
    assert crop.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize(
    ("text", "says"),
    [
        ("", "empty"),
        ('{"format": "other"}\n', "not a map-updates file"),
        ('{"format": "pmnav-map-updates", "version": 9, "building": "x"}\n', "version 9"),
        ('{"format": "pmnav-map-updates", "version": 1, "building": "x"}\n{oops\n', "line 2"),
        ('{"format": "pmnav-map-updates", "version": 1, "building": "x"}\n{"kind": "gone"}\n',
         "kind 'gone'"),
    ],
)  # fmt: skip
def test_a_bad_updates_file_is_one_clear_line(tmp_path, capsys, text, says):
    bad = tmp_path / "bad.jsonl"
    bad.write_text(text, encoding="utf-8")
    with pytest.raises(MapUpdatesError, match=says):
        load_updates(bad)
    assert _pmnav("map", "updates", str(bad)) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(bad) in err and says in err


def test_a_crop_outside_the_folder_is_refused(tmp_path):
    path = _write(tmp_path, [_renamed()])
    lines = path.read_text().splitlines()
    rec = json.loads(lines[1])
    rec["evidence"]["crop"] = "../../etc/passwd"
    path.write_text("\n".join([lines[0], json.dumps(rec)]) + "\n")
    with pytest.raises(MapUpdatesError, match="beside the updates file"):
        load_updates(path)


def _copy_of_fig2(tmp_path):
    dst = tmp_path / "fig2.yaml"
    shutil.copy(resolve_building_path("fig2_hospital"), dst)
    return dst


def test_listing_names_places_in_the_buildings_words_and_changes_nothing(tmp_path, capsys):
    building = _copy_of_fig2(tmp_path)
    before = building.read_text()
    path = _write(tmp_path, [_renamed(), _moved()], building=str(building))
    assert _pmnav("map", "updates", str(path)) == 0
    out = capsys.readouterr().out
    assert "sign_text" in out and "moved" in out
    assert "room8 '108', on the corridor between" in out
    assert "seen '108 Quiet Room'; 2 read(s)" in out
    assert building.read_text() == before and not list(tmp_path.glob("*.bak"))


def test_accepting_one_update_changes_the_building_and_keeps_a_backup(tmp_path, capsys):
    building = _copy_of_fig2(tmp_path)
    before = building.read_text()
    path = _write(tmp_path, [_moved(), _renamed()], building=str(building))
    assert _pmnav("map", "updates", str(path), "--accept", "2") == 0
    out = capsys.readouterr().out
    assert "+  sign: 108 Quiet Room" in out  # the diff is shown
    b = load_building(building)  # loads and validates
    assert b.room("room8").sign_text == "108 Quiet Room"
    assert b.landmark("elevator1").pos == (37.4, 6.0)  # not accepted: unchanged
    assert (tmp_path / "fig2.yaml.bak").read_text() == before


def test_a_built_in_building_is_only_written_as_a_copy(tmp_path, capsys):
    path = _write(tmp_path, [_renamed()])
    assert _pmnav("map", "updates", str(path), "--accept", "1") == 2
    assert "--out" in capsys.readouterr().err
    out = tmp_path / "new.yaml"
    assert _pmnav("map", "updates", str(path), "--accept", "all", "--out", str(out)) == 0
    assert load_building(out).room("room8").sign_text == "108 Quiet Room"
    assert load_building("fig2_hospital").room("room8").sign_text == "108"


def test_a_choice_out_of_range_is_one_line(tmp_path, capsys):
    path = _write(tmp_path, [_renamed()])
    assert _pmnav("map", "updates", str(path), "--accept", "1,4") == 2
    assert "expected numbers 1 to 1" in capsys.readouterr().err
