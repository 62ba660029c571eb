"""``pmnav sim belief``: the localization run in the simulator, its belief drawn step by
step."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from pmnav_bt.experiments.sim_cli import app


@pytest.mark.slow  # a localization run in pybullet: about a minute
def test_the_belief_is_drawn_after_each_look_and_drive_of_a_run(tmp_path):
    r = CliRunner().invoke(app, ["belief", "--out", str(tmp_path)])
    assert r.exit_code == 0, r.output
    assert "fixed after" in r.output
    steps = sorted(tmp_path.glob("step_*.png"))
    assert len(steps) >= 2  # a look round, then the drive and the fix at least
    assert (tmp_path / "steps.png").is_file()
    assert str(tmp_path / "steps.png") in r.output.replace("\n", "")
