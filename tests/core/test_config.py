"""The typed run configuration: defaults, file, overrides, errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from pmnav_bt.config import Config, load_config
from pmnav_bt.config_doc import COMMAND, config_doc
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
        (["tree.variant=fast"], "tree.variant: unknown tree variant 'fast'"),  # at load
        (["tree.variant=1"], "tree.variant"),  # a name
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


def test_every_key_is_described():
    bare = [
        f"{name}.{key}"
        for name, section in Config.model_fields.items()
        for key, field in section.annotation.model_fields.items()
        if not field.description
    ]
    assert not bare, f"give these keys a Field(description=...) for docs/config.md: {bare}"


def test_docs_config_md_is_the_generators_output():
    """docs/config.md is generated; a key added or re-described without regenerating it
    (``python -m pmnav_bt.config_doc > docs/config.md``) fails here."""
    page = (Path(__file__).resolve().parents[2] / "docs" / "config.md").read_text()
    assert page == config_doc(), f"docs/config.md is stale: run {COMMAND}"


def test_the_page_shows_each_keys_default_bounds_and_meaning():
    page = config_doc()
    assert (
        "| `ocr_threads` | `1` | integer >= 1 | ocr, gdino_sam: onnxruntime threads per model |"
        in page
    )
    assert "| `search_range` | unset | number > 0.0, <= 100.0, or unset |" in page
    assert "| `door_side` | `'left'` | `left` \\| `right` |" in page
    assert "| `planner` | `graph` | shortest path on the priori-map graph |" in page
