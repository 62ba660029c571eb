"""The building editor behind 'pmnav annotate': edits, undo, checks, saving."""

from __future__ import annotations

import pytest

from pmnav_bt.map.catalogue import load_building, resolve_building_path
from pmnav_bt.map.edit import BuildingEditor, EditError


@pytest.fixture
def editor(tmp_path):
    f = tmp_path / "b.yaml"
    f.write_text(resolve_building_path("l_hospital").read_text())
    return BuildingEditor.open(f)


def test_add_move_rename_undo(editor):
    rid = editor.add_room((20.0, -1.2), name="Gift Shop")
    assert rid == "room32" and editor.position(rid) == (20.0, -1.2)
    editor.move(rid, (21.0, -1.2))
    editor.set_fields(rid, aliases="shop, kiosk", sign="Gift Shop")
    assert editor.find(rid)[1]["aliases"] == ["shop", "kiosk"]
    editor.undo()
    editor.undo()
    assert editor.position(rid) == (20.0, -1.2)
    editor.undo()
    with pytest.raises(EditError):
        editor.find(rid)


def test_renaming_a_waypoint_renames_its_edges(editor):
    editor.set_fields("turn1", id="corner")
    assert editor.building().corridor_graph().degree("corner") == 2


def test_deleting_a_waypoint_takes_its_edges_and_problems_say_so(editor):
    editor.delete("end1")
    assert all("end1" not in (a, b) for a, b, _ in editor.edge_ends())
    assert any("turn1" in p and "error" in p for p in editor.problems())


def test_duplicate_id_is_refused(editor):
    with pytest.raises(EditError, match="taken"):
        editor.add_room((1, 1), ident="room1")


def test_save_round_trips(editor, tmp_path):
    editor.add_landmark((20.0, 1.2), name="Cafe", sign="Cafe")
    editor.save(tmp_path / "out.yaml")
    assert load_building(tmp_path / "out.yaml") == editor.building()


def test_invalid_state_is_saved_as_it_stands(editor, tmp_path):
    editor.delete("end1")
    editor.save(tmp_path / "half.yaml")
    again = BuildingEditor({}, None)
    import yaml

    again.data = yaml.safe_load((tmp_path / "half.yaml").read_text())
    assert again.data["edges"] == editor.data["edges"]
