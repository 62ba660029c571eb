"""The pmnav CLI: commands, output forms, and one-line errors with non-zero exits."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from pmnav_bt.experiments.cli import main  # the pmnav program (with pmnav plan)


def run(capsys, *argv) -> tuple[int, str, str]:
    with pytest.raises(SystemExit) as info:
        main(list(argv))
    out, err = capsys.readouterr()
    return info.value.code or 0, out, err


def test_validate_ok(capsys):
    code, out, _ = run(capsys, "validate", "fig2_hospital")
    assert code == 0 and "OK" in out and "20 rooms" in out


def test_validate_lists_every_problem(capsys, tmp_path):
    f = tmp_path / "bad.yaml"
    f.write_text(
        "schema_version: 1\nname: bad\nwaypoints:\n"
        " - {id: a, kind: start, pos: [0, 0]}\n - {id: b, kind: end, pos: [9, 0], colour: 1}\n"
        "edges: [[a, b], [a, z]]\n"
    )
    code, _, err = run(capsys, "validate", str(f))
    assert code == 1
    lines = err.strip().splitlines()
    assert lines[-1] == "1 problem(s)" and "colour: unknown key" in lines[0]
    assert str(f) in lines[0]


def test_map_text_json(capsys):
    code, out, _ = run(capsys, "map", "fig2_hospital")
    assert code == 0 and "seg13(room14-room7)" in out
    code, out, _ = run(capsys, "map", "fig2_hospital", "--json")
    assert json.loads(out)["segments"][12]["name"] == "seg13(room14-room7)"


def test_plan_text_and_json(capsys):
    code, out, _ = run(capsys, "plan", "fig2_hospital", "--from", "seg13", "--to", "room 17")
    assert code == 0 and "{room8: go straight} -> {turn2: turn left}" in out
    code, out, _ = run(capsys, "plan", "fig2_hospital", "--from", "seg13", "--to", "OSSC", "--json")
    assert json.loads(out)["goal"]["room"] == "room17"


@pytest.mark.parametrize(
    "argv, words",
    [
        (["plan", "fig2_hospital", "--from", "seg13", "--to", "room71"], "no room called 'room71'"),
        (["plan", "fig2_hospital", "--from", "seg99", "--to", "room7"], "unknown segment"),
        (["plan", "nosuch", "--from", "seg1", "--to", "room7"], "no built-in building"),
        (["map", "/nonexistent/b.yaml"], "cannot read building file"),
    ],
)
def test_user_errors_are_one_line_exit_2(capsys, argv, words):
    code, out, err = run(capsys, *argv)
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("pmnav: error: ") and words in err


def test_console_script_prints_no_traceback(tmp_path):
    f = tmp_path / "b.yaml"
    f.write_text("schema_version: 1\nname: x\nwaypoints: [}\n")
    r = subprocess.run(
        [sys.executable, "-m", "pmnav_bt.cli", "map", str(f)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert "not valid YAML" in r.stderr and r.stderr.count("\n") == 1


def test_buildings_lists_builtins(capsys):
    code, out, _ = run(capsys, "buildings")
    assert code == 0 and "fig2_hospital" in out and "loop_school" in out
