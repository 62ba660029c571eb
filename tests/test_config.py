"""The typed run configuration: defaults, file, overrides, errors."""

from __future__ import annotations

import pytest

from pmnav_bt.config import load_config
from pmnav_bt.errors import ConfigError


def test_defaults_and_overrides(tmp_path):
    assert load_config().tree.variant == "pmnav"
    f = tmp_path / "c.yaml"
    f.write_text("grounder: {miss_rate: 0.2}\ntree: {tick_hz: 5}\n")
    c = load_config(f, ["tree.variant=coarse_only", "grounder.false_positive_rate=0.1"])
    assert (c.grounder.miss_rate, c.grounder.false_positive_rate) == (0.2, 0.1)
    assert c.tree.tick_hz == 5 and c.tree.variant == "coarse_only"


@pytest.mark.parametrize(
    "overrides, words",
    [
        (["grounder.miss_rate=2"], "grounder.miss_rate"),
        (["tree.variant=1"], "tree.variant"),  # a name; unknown names: tests/trees/test_variants.py
        (["grounder.colour=red"], "grounder.colour"),
        (["novalue"], "expected section.key=value"),
    ],
)
def test_bad_values_name_the_field(overrides, words):
    with pytest.raises(ConfigError, match=words.replace(".", r"\.")):
        load_config(None, overrides)


def test_bad_file(tmp_path):
    with pytest.raises(ConfigError, match="cannot read"):
        load_config(tmp_path / "none.yaml")
    f = tmp_path / "l.yaml"
    f.write_text("- 1\n")
    with pytest.raises(ConfigError, match="mapping"):
        load_config(f)
