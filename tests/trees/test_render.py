"""Tree pictures: the .dot names every node with py_trees' shapes; SVG/PNG with Graphviz; a
clear one-line error (and the .dot still written) without it; ``pmnav tree render``."""

from __future__ import annotations

import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

import py_trees
import pytest
from py_trees.common import Status
from typer.testing import CliRunner

from pmnav_bt.errors import PmNavError
from pmnav_bt.trees.cli import app
from pmnav_bt.trees.render import (
    GraphvizMissingError,
    log_nodes,
    render_log_tick,
    render_tree,
    tree_nodes,
)
from pmnav_bt.trees.snapshots import structure

HAS_DOT = shutil.which("dot") is not None
needs_dot = pytest.mark.skipif(not HAS_DOT, reason="Graphviz 'dot' is not installed")


def small_root() -> py_trees.behaviour.Behaviour:
    choose = py_trees.composites.Selector(
        "Choose",
        memory=False,
        children=[py_trees.behaviours.Failure(name="Same"), py_trees.behaviours.Success("Go")],
    )
    job = py_trees.composites.Sequence(
        "Job",
        memory=True,
        children=[
            py_trees.decorators.Retry("Again", choose, num_failures=3),
            py_trees.behaviours.Success(name="Same"),  # a second node named Same
            py_trees.behaviours.Running(name='Odd "name" \\ here'),
        ],
    )
    return py_trees.composites.Parallel(
        "Root",
        policy=py_trees.common.ParallelPolicy.SuccessOnOne(),
        children=[py_trees.behaviours.Running(name="Watch"), job],
    )


def dot_nodes(text: str) -> dict[str, str]:
    """Node id -> its attribute list, from our .dot output (one statement per line)."""
    out = {}
    for line in text.splitlines():
        if line.startswith('"') and "->" not in line and "[" in line:
            node_id, _, attrs = line.partition(" [")
            out[node_id.strip('"')] = attrs
    return out


def test_dot_names_every_node_with_its_shape(tmp_path):
    root = small_root()
    written = render_tree(root, tmp_path, "small", formats=("dot",))
    assert set(written) == {"dot"} and written["dot"] == tmp_path / "small.dot"
    text = written["dot"].read_text()
    nodes = dot_nodes(text)
    assert set(nodes) == {str(n.id) for n in root.iterate()}  # both "Same" nodes, by id
    by_name = {n.name: nodes[str(n.id)] for n in root.iterate()}
    assert "shape=parallelogram" in by_name["Root"] and "SuccessOnOne" in by_name["Root"]
    assert "shape=box" in by_name["Job"] and "Sequence, memory" in by_name["Job"]
    assert "shape=octagon" in by_name["Choose"] and "Selector, reactive" in by_name["Choose"]
    assert "fillcolor=ghostwhite" in by_name["Again"] and "Retry up to 3 tries" in by_name["Again"]
    assert "fillcolor=gray" in by_name["Watch"]
    assert r'label="Odd \"name\" \\ here' in text  # quoted for Graphviz
    assert text.count("->") == len(nodes) - 1


def test_colours_by_status(tmp_path):
    root = small_root()
    tree = py_trees.trees.BehaviourTree(root)
    tree.tick()
    ids = {n.name: str(n.id) for n in root.iterate()}
    status = {str(n.id): n.status.name for n in root.iterate() if n.status != Status.INVALID}
    feedback = {ids["Watch"]: "watching"}
    path = render_tree(root, tmp_path, "t", formats=("dot",), status=status, feedback=feedback)
    nodes = dot_nodes(path["dot"].read_text())
    assert "fillcolor=lightskyblue" in nodes[ids["Watch"]] and "watching" in nodes[ids["Watch"]]
    assert "fillcolor=palegreen" in nodes[ids["Go"]]
    fails, succeeds = (
        next(n for n in root.iterate() if isinstance(n, cls))
        for cls in (py_trees.behaviours.Failure, py_trees.behaviours.Success)
    )
    assert "fillcolor=salmon" in nodes[str(fails.id)]
    assert "fillcolor=palegreen" in nodes[str(succeeds.id)]
    untouched = render_tree(root, tmp_path, "u", formats=("dot",), status={})["dot"]
    assert all("fillcolor=white" in a for a in dot_nodes(untouched.read_text()).values())


def test_collapse_decorators_folds_them_into_their_child(tmp_path):
    root = small_root()
    text = render_tree(root, tmp_path, "c", formats=("dot",), collapse_decorators=True)[
        "dot"
    ].read_text()
    nodes = dot_nodes(text)
    again = next(n for n in root.iterate() if n.name == "Again")
    assert str(again.id) not in nodes
    choose = nodes[str(again.decorated.id)]
    assert "Again: Retry up to 3 tries" in choose
    job = next(n for n in root.iterate() if n.name == "Job")
    assert f'"{job.id}" -> "{again.decorated.id}"' in text
    assert text.count("->") == len(nodes) - 1


def test_log_nodes_read_kinds_from_class_names():
    root = small_root()
    live = {n.id: n.kind for n in tree_nodes(root)}
    logged = {n.id: n.kind for n in log_nodes(structure(root))}
    assert logged == live


@needs_dot
def test_svg_and_png_with_graphviz(tmp_path):
    root = small_root()
    written = render_tree(root, tmp_path, "small")
    assert set(written) == {"dot", "svg", "png"}
    assert written["png"].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    svg = ET.parse(written["svg"]).getroot()
    texts = {t.text for t in svg.iter("{http://www.w3.org/2000/svg}text")}
    for name in ("Root", "Job", "Choose", "Again", "Go", "Watch", "Retry up to 3 tries"):
        assert name in texts


def test_without_graphviz_writes_dot_and_says_how_to_get_svg(tmp_path, monkeypatch):
    empty = tmp_path / "empty_bin"
    empty.mkdir()
    monkeypatch.setenv("PATH", str(empty))  # no 'dot' anywhere
    with pytest.raises(GraphvizMissingError) as info:
        render_tree(small_root(), tmp_path / "out", "small")
    msg = str(info.value)
    dot_file = tmp_path / "out" / "small.dot"
    assert dot_file.is_file() and info.value.written == {"dot": dot_file}
    assert "apt-get install graphviz" in msg and str(dot_file) in msg and "\n" not in msg
    assert isinstance(info.value, PmNavError)
    # asking for the .dot only needs nothing
    assert set(render_tree(small_root(), tmp_path, "only", formats=["dot"])) == {"dot"}


def test_unknown_format(tmp_path):
    with pytest.raises(PmNavError, match="unknown picture format 'pdf'"):
        render_tree(small_root(), tmp_path, "x", formats=("dot", "pdf"))


def test_cli_renders_the_real_pmnav_tree(tmp_path):
    from pmnav_bt.map.catalogue import load_building
    from pmnav_bt.trees.cli import RENDER_BUILDING

    res = CliRunner().invoke(app, ["render", "--out", str(tmp_path), "--format", "dot"])
    assert res.exit_code == 0, res.output
    assert res.stdout.strip() == f"wrote {tmp_path / 'pmnav.dot'}"
    text = (tmp_path / "pmnav.dot").read_text()
    for name in (
        "PM-Nav",
        "Monitor",
        "LocalizeViews",
        "CoarseDirection",
        "Grounding",
        "FineDirection",
        "Verification",
        "CornerCheck",
        "ForkChoice",
        "Relocalize",
        "Arrive",
    ):
        assert f'label="{name}' in text or f"label={name}" in text, name
    assert "StepTimeout\\nClockTimeout" in text
    assert load_building(RENDER_BUILDING)  # the built-in the command uses


def test_cli_render_errors():
    res = CliRunner().invoke(app, ["render", "--variant", "fancy"])
    assert "--variant 'fancy': choose from pmnav, coarse_only" in str(res.exception)
    res = CliRunner().invoke(app, ["render", "--tick", "3"])
    assert "--tick needs --log" in str(res.exception)
    res = CliRunner().invoke(app, ["render", "--format", "svg,gif"])
    assert "--format 'svg,gif'" in str(res.exception)


def test_cli_renders_a_logged_tick(tmp_path):
    from pmnav_bt.trees.snapshots import Replay, SnapshotLogger

    tree = py_trees.trees.BehaviourTree(small_root())
    log = tmp_path / "tree.jsonl"
    with open(log, "w", encoding="utf-8") as out:
        tree.add_post_tick_handler(SnapshotLogger(tree, out))
        tree.tick()
        tree.tick()
    res = CliRunner().invoke(
        app, ["render", "--log", str(log), "--tick", "1", "--out", str(tmp_path), "--format", "dot"]
    )
    assert res.exit_code == 0, res.output
    text = (tmp_path / "tree_tick1.dot").read_text()
    assert "tree.jsonl: tick 1" in text and "fillcolor=lightskyblue" in text
    rp = Replay.load(log)
    again = render_log_tick(rp.nodes, tmp_path, "again", rp.ticks[1], formats=("dot",))
    assert again["dot"].read_text().count("->") == len(rp.nodes) - 1
    res = CliRunner().invoke(app, ["render", "--log", str(log), "--tick", "9"])
    assert "no tick 9 in this log (it holds ticks 0..1)" in str(res.exception)


def test_cli_module_imports_neither_py_trees_nor_pybullet():
    code = (
        "import sys, pmnav_bt.trees.cli; "
        "bad = [m for m in ('py_trees', 'pybullet') if m in sys.modules]; "
        "sys.exit(', '.join(bad) if bad else 0)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
