"""Draw a behaviour tree as a picture: Graphviz .dot always, .svg and .png when ``dot`` is
installed.

The drawing keeps py_trees' own vocabulary (``py_trees.display.dot_tree``): a box is a
Sequence, an octagon a Selector, a parallelogram a Parallel, a white ellipse a decorator and
a grey ellipse a leaf. It differs where that function falls short for a debugging picture of
a large tree: nodes are keyed by behaviour id (two leaves may share a name), a second line
names each node's class and settings (memory, retry count, timeout), decorators can be folded
into the node they decorate, and nodes can be coloured by their status at one tick of a
snapshot log. The same code draws a live tree and a tree read back from a log
(:class:`pmnav_bt.trees.snapshots.Replay`), so a failure can be drawn after the fact.
"""

from __future__ import annotations

import shutil
import subprocess
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path

import py_trees
import pydot

from pmnav_bt.errors import PmNavError

GRAPHVIZ_HINT = "apt-get install graphviz (macOS: brew install graphviz)"
FORMATS = ("dot", "svg", "png")
FONT = "Helvetica"

# py_trees' shapes and colours (py_trees.display.dot_tree), by node kind.
KIND_STYLE = {
    "sequence": ("box", "orange"),
    "selector": ("octagon", "cyan"),
    "parallel": ("parallelogram", "gold"),
    "decorator": ("ellipse", "ghostwhite"),
    "leaf": ("ellipse", "gray"),
}
STATUS_FILL = {
    "SUCCESS": "palegreen",
    "FAILURE": "salmon",
    "RUNNING": "lightskyblue",
    "INVALID": "gray90",
}
COMPOSITE_CLASSES = {"Sequence": "sequence", "Selector": "selector", "Parallel": "parallel"}
DECORATOR_CLASSES = {
    "Retry",
    "Repeat",
    "Timeout",
    "ClockTimeout",
    "FailureIsSuccess",
    "FailureIsRunning",
    "SuccessIsFailure",
    "SuccessIsRunning",
    "RunningIsFailure",
    "RunningIsSuccess",
    "Inverter",
    "OneShot",
    "Condition",
    "EternalGuard",
    "Count",
    "StatusToBlackboard",
    "PassThrough",
}


class GraphvizMissingError(PmNavError):
    """SVG or PNG was asked for but Graphviz's ``dot`` is not on PATH; the .dot file was
    written (``written`` maps each written format to its path)."""

    def __init__(self, dot_path: Path, written: dict[str, Path]):
        self.dot_path = dot_path
        self.written = written
        super().__init__(
            f"SVG and PNG need Graphviz's 'dot' program: {GRAPHVIZ_HINT}; "
            f"the .dot file is at {dot_path}"
        )


@dataclass(frozen=True)
class NodeInfo:
    """One node to draw: ``kind`` is sequence/selector/parallel/decorator/leaf and
    ``detail`` the settings shown under the name (memory, policy, retry count, ...)."""

    id: str
    name: str
    cls: str
    parent: str | None
    kind: str
    detail: str = ""


def _kind(node: py_trees.behaviour.Behaviour) -> str:
    if isinstance(node, py_trees.composites.Selector):
        return "selector"
    if isinstance(node, py_trees.composites.Sequence):
        return "sequence"
    if isinstance(node, py_trees.composites.Parallel):
        return "parallel"
    if isinstance(node, py_trees.decorators.Decorator):
        return "decorator"
    return "sequence" if node.children else "leaf"


def _detail(node: py_trees.behaviour.Behaviour) -> str:
    cls = type(node).__name__
    if isinstance(node, py_trees.composites.Parallel):
        return f"{cls} {type(node.policy).__name__}"
    if isinstance(node, py_trees.composites.Composite):
        return f"{cls}, memory" if getattr(node, "memory", False) else f"{cls}, reactive"
    if isinstance(node, py_trees.decorators.Retry):
        return f"{cls} up to {node.num_failures} tries"
    if isinstance(node, py_trees.decorators.Repeat):
        n = node.num_success
        return f"{cls} until failure" if n < 0 else f"{cls} {n} times"
    duration = getattr(node, "duration", None)
    if isinstance(node, py_trees.decorators.Decorator) and isinstance(duration, (int, float)):
        return f"{cls} {duration:g} s"
    return cls


def tree_nodes(root: py_trees.behaviour.Behaviour) -> list[NodeInfo]:
    """The nodes of a live tree, depth-first pre-order, with kinds and settings."""
    out: list[NodeInfo] = []

    def walk(node: py_trees.behaviour.Behaviour, parent: str | None) -> None:
        out.append(
            NodeInfo(
                str(node.id), node.name, type(node).__name__, parent, _kind(node), _detail(node)
            )
        )
        for c in node.children:
            walk(c, str(node.id))

    walk(root, None)
    return out


def log_nodes(records: Iterable[Mapping]) -> list[NodeInfo]:
    """The nodes of a snapshot log's ``tree`` record (``Replay.nodes``); the kind is read
    from the class name, or from the number of children for classes the log cannot say."""
    records = list(records)
    n_children: dict[str | None, int] = {}
    for r in records:
        n_children[r["parent"]] = n_children.get(r["parent"], 0) + 1
    out = []
    for r in records:
        cls = r["class"]
        n = n_children.get(r["id"], 0)
        if cls in COMPOSITE_CLASSES:
            kind = COMPOSITE_CLASSES[cls]
        elif cls in DECORATOR_CLASSES or n == 1:
            kind = "decorator"
        else:
            kind = "sequence" if n else "leaf"
        out.append(NodeInfo(r["id"], r["name"], cls, r["parent"], kind, cls))
    return out


def dot_graph(
    nodes: list[NodeInfo],
    status: Mapping[str, str] | None = None,
    feedback: Mapping[str, str] | None = None,
    rankdir: str = "TB",
    collapse_decorators: bool = False,
    title: str | None = None,
) -> pydot.Dot:
    """A pydot graph of ``nodes``. With ``status`` (id -> SUCCESS/FAILURE/RUNNING/INVALID,
    as in a snapshot log's tick) nodes are filled by status, and nodes not ticked are drawn
    faded; ``feedback`` adds each node's feedback message under its name."""
    feedback = feedback or {}
    by_id = {n.id: n for n in nodes}
    graph = pydot.Dot(graph_type="digraph", ordering="out", rankdir=rankdir, bgcolor="white")
    graph.set_name("tree")
    graph.set_graph_defaults(fontname=FONT, fontsize="10", nodesep="0.2", ranksep="0.35")
    graph.set_node_defaults(fontname=FONT, fontsize="11", margin="0.08,0.03", height="0.3")
    graph.set_edge_defaults(arrowsize="0.6", color="gray30")

    folded: dict[str, list[str]] = {}  # child id -> the decorators folded into it, outer first
    shown: dict[str, str] = {}  # node id -> the id of the node drawn for it

    def drawn(node_id: str) -> str:
        return shown.get(node_id, node_id)

    children: dict[str | None, list[NodeInfo]] = {}
    for n in nodes:
        children.setdefault(n.parent, []).append(n)
    if collapse_decorators:
        for n in nodes:  # pre-order: outer decorators first
            kids = children.get(n.id, [])
            if n.kind == "decorator" and len(kids) == 1:
                child = kids[0]
                folded[child.id] = folded.pop(n.id, []) + [n.id]
                for d in folded[child.id]:
                    shown[d] = child.id

    for n in nodes:
        if n.id in shown:
            continue
        lines = [f"{by_id[d].name}: {by_id[d].detail}" for d in folded.get(n.id, [])]
        lines += [n.name]
        if n.detail and n.detail != n.name:
            lines.append(f"({n.detail})" if n.kind == "leaf" else n.detail)
        shape, fill = KIND_STYLE[n.kind]
        attrs = {"shape": shape, "style": "filled", "fillcolor": fill}
        if status is not None:
            st = status.get(n.id) or next(
                (status[d] for d in folded.get(n.id, []) if d in status), None
            )
            if st is None:
                attrs.update(fillcolor="white", color="gray60", fontcolor="gray50")
            else:
                attrs.update(fillcolor=STATUS_FILL.get(st, "white"), penwidth="2")
            fb = feedback.get(n.id)
            if fb:
                lines.append(f'"{_clip(fb, 40)}"')
        attrs["label"] = "\n".join(_escape(s) for s in lines)
        tip = f"{n.name} ({n.cls})"
        if status is not None and feedback.get(n.id):
            tip += f": {feedback[n.id]}"
        attrs["tooltip"] = _escape(tip)  # shown on hover in the SVG, unclipped
        graph.add_node(pydot.Node(n.id, **attrs))
        outer = by_id[folded[n.id][0]] if n.id in folded else n
        if outer.parent is not None:
            graph.add_edge(pydot.Edge(drawn(outer.parent), n.id))

    ellipses = (
        "ellipse: decorator or leaf"
        if status is not None
        else "white ellipse: decorator   grey ellipse: leaf"
    )
    legend = [
        f"box: Sequence   octagon: Selector   parallelogram: Parallel   {ellipses}",
        "memory: resumes its running child;  reactive: restarts from the first child each tick",
    ]
    if status is not None:
        legend.append("fill: green SUCCESS, red FAILURE, blue RUNNING, white not ticked")
    graph.set_label("\n".join(_escape(s) for s in ([title] if title else []) + legend))
    graph.set("labelloc", "b")
    return graph


def _clip(text: str, limit: int) -> str:
    return text if len(text) <= limit else text[: limit - 1] + "…"


def _escape(text: str) -> str:
    """Graphviz reads a backslash as an escape (\\n, \\l, ...); pydot quotes the rest."""
    return text.replace("\\", "\\\\")


def graphviz_available() -> bool:
    """Whether Graphviz's ``dot`` program is on PATH."""
    return shutil.which("dot") is not None


def write_graph(
    graph: pydot.Dot, out_dir: str | Path, name: str, formats: Iterable[str] = FORMATS
) -> dict[str, Path]:
    """Write ``graph`` as ``out_dir/name.dot`` and, with Graphviz, .svg/.png.

    Returns {format: path}. Raises :class:`GraphvizMissingError` (after writing the .dot) when
    svg or png is asked for and ``dot`` is not on PATH."""
    formats = list(formats)
    unknown = [f for f in formats if f not in FORMATS]
    if unknown:
        raise PmNavError(f"unknown picture format {unknown[0]!r}; choose from {', '.join(FORMATS)}")
    out = Path(out_dir)
    try:
        out.mkdir(parents=True, exist_ok=True)
        dot_path = out / f"{name}.dot"
        dot_path.write_text(graph.to_string(), encoding="utf-8")
    except OSError as err:
        raise PmNavError(f"{out}: cannot write the tree picture: {err.strerror}") from None
    written = {"dot": dot_path}
    pictures = [f for f in formats if f != "dot"]
    if not pictures:
        return written
    dot = shutil.which("dot")
    if dot is None:
        raise GraphvizMissingError(dot_path, written)
    for fmt in pictures:
        path = out / f"{name}.{fmt}"
        args = [dot, f"-T{fmt}", str(dot_path), "-o", str(path)]
        if fmt == "png":
            args.insert(1, "-Gdpi=110")
        try:
            subprocess.run(args, check=True, capture_output=True, text=True, timeout=120)
        except subprocess.CalledProcessError as err:
            msg = (err.stderr or "").strip().splitlines()
            raise PmNavError(
                f"Graphviz could not draw {path}: {msg[-1] if msg else err}; "
                f"the .dot file is at {dot_path}"
            ) from None
        except subprocess.TimeoutExpired:
            raise PmNavError(
                f"Graphviz took over 120 s to draw {path}; the .dot file is at {dot_path}"
            ) from None
        written[fmt] = path
    return written


def render_tree(
    root: py_trees.behaviour.Behaviour,
    out_dir: str | Path,
    name: str,
    *,
    formats: Iterable[str] = FORMATS,
    status: Mapping[str, str] | None = None,
    feedback: Mapping[str, str] | None = None,
    rankdir: str = "TB",
    collapse_decorators: bool = False,
    title: str | None = None,
) -> dict[str, Path]:
    """Draw the tree under ``root`` to ``out_dir/name.{dot,svg,png}``; returns {format: path}.

    ``status``/``feedback`` are a snapshot tick's maps (behaviour id as a string -> value),
    for instance ``Replay.ticks[i]["status"]``; see :func:`dot_graph`. Raises
    :class:`GraphvizMissingError` (a PmNavError naming the .dot file, which is written) when
    Graphviz is absent and svg or png is asked for; pass ``formats=("dot",)`` to need nothing.
    """
    graph = dot_graph(
        tree_nodes(root),
        status=status,
        feedback=feedback,
        rankdir=rankdir,
        collapse_decorators=collapse_decorators,
        title=title,
    )
    return write_graph(graph, out_dir, name, formats)


def render_log_tick(
    nodes: Iterable[Mapping],
    out_dir: str | Path,
    name: str,
    tick: Mapping | None = None,
    *,
    formats: Iterable[str] = FORMATS,
    rankdir: str = "TB",
    collapse_decorators: bool = False,
    title: str | None = None,
) -> dict[str, Path]:
    """Draw a tree read back from a snapshot log (``Replay.nodes``), coloured by the
    statuses of one of its tick records (``Replay.ticks[i]``) when ``tick`` is given."""
    graph = dot_graph(
        log_nodes(nodes),
        status=tick["status"] if tick is not None else None,
        feedback=tick["feedback"] if tick is not None else None,
        rankdir=rankdir,
        collapse_decorators=collapse_decorators,
        title=title,
    )
    return write_graph(graph, out_dir, name, formats)
