"""'pmnav annotate' without a display: one line that says how to run it."""

from __future__ import annotations

import pytest

from pmnav_bt.cli import main


def test_annotate_without_a_display_says_how(monkeypatch, capsys, tmp_path):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    f = tmp_path / "my building.yaml"
    with pytest.raises(SystemExit) as ex:
        main(["annotate", str(f)])
    assert ex.value.code == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "DISPLAY is not set" in err
    assert f"xvfb-run -a pmnav annotate '{f}'" in err  # quoted for the shell
    assert "ssh -X" in err and "docs/real-maps.md" in err
