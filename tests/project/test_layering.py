"""Layering, by import analysis of every module (imports inside functions included):
the core imports none of the layers built on it; ``experiments`` is the one layer that
joins simulator, tree and metrics; no layer's modules import each other in a circle. And
every third-party import is a declared dependency."""

from __future__ import annotations

import ast
import importlib.metadata
import re
import sys
from pathlib import Path

import networkx as nx
import pytest

tomllib = pytest.importorskip("tomllib")  # Python 3.11+

ROOT = Path(__file__).resolve().parents[2]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())

# layer -> the layers it may import besides the core (which every layer may import)
ALLOWED = {
    "core": set(),
    "behaviours": set(),
    "trees": {"behaviours"},
    "sim": set(),
    "hardware": {"behaviours", "trees", "sim"},  # the node runs the tree; sim_create3 the sim
    "experiments": {"behaviours", "trees", "sim"},
}
SUBLAYERS = ("behaviours", "trees", "sim", "hardware", "experiments")


def layer_of_module(name: str) -> str | None:
    """'pmnav_bt.sim.world' -> 'sim'; 'pmnav_bt.map.building' -> 'core'; numpy -> None."""
    parts = name.split(".")
    if parts[0] != "pmnav_bt":
        return None
    if len(parts) > 1 and parts[1] in SUBLAYERS:
        return parts[1]
    return "core"


def modules_under(package: str, folder: Path) -> dict[str, Path]:
    """The modules of ``package``, whose files are in ``folder``: import name -> file."""
    out = {}
    for path in folder.rglob("*.py"):
        rel = path.relative_to(folder).with_suffix("").parts
        out[".".join([package, *(p for p in rel if p != "__init__")])] = path
    return out


def shipped_modules() -> dict[str, Path]:
    """Every module of the wheel: import name -> file."""
    out = {}
    for package, folder in PYPROJECT["tool"]["setuptools"]["package-dir"].items():
        for name, path in modules_under(package, ROOT / folder).items():
            top = name.split(".")[1] if package == "pmnav_bt" and "." in name else None
            if top in SUBLAYERS and top != "experiments":
                continue  # installed from its own folder
            out[name] = path
    return out


def _fallbacks(tree: ast.AST) -> set[int]:
    """ids of the import nodes in ``except ImportError:`` handlers (optional fallbacks)."""
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ExceptHandler) and "ImportError" in ast.unparse(node.type or ""):
            out |= {id(n) for n in ast.walk(node) if isinstance(n, (ast.Import, ast.ImportFrom))}
    return out


def imports(path: Path, module: str, fallbacks: bool = True) -> list[tuple[int, str]]:
    """(line, absolute module name) of every import in the file, at any depth (with or
    without the fallbacks in ``except ImportError`` handlers)."""
    out = []
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    tree = ast.parse(path.read_text(encoding="utf-8"))
    skip = set() if fallbacks else _fallbacks(tree)
    for node in ast.walk(tree):
        if id(node) in skip:
            continue
        if isinstance(node, ast.Import):
            out += [(node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                up = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*up, base] if base else up)
            out += [
                (node.lineno, f"{base}.{a.name}" if a.name != "*" else base) for a in node.names
            ]
    return out


def import_graph(modules: dict[str, Path]) -> nx.DiGraph:
    """module -> each module of ``modules`` it imports, from any line of its file (the
    module's top, a function's body, an ``if TYPE_CHECKING:`` block): what ``imports``
    finds by walking the file's syntax tree. ``from pmnav_bt.map.building import Building``
    is an edge to ``pmnav_bt.map.building``, the longest module name the import starts with."""
    graph = nx.DiGraph()
    graph.add_nodes_from(modules)
    for name, path in modules.items():
        for _, target in imports(path, name):
            while target and target not in modules:
                target = target.rpartition(".")[0]
            if target and target != name:
                graph.add_edge(name, target)
    return graph


def import_cycles(modules: dict[str, Path]) -> list[list[str]]:
    """Every circle of imports among ``modules`` (networkx ``simple_cycles``), each one
    starting at its first module in alphabetical order; sorted."""
    out = []
    for cycle in nx.simple_cycles(import_graph(modules)):
        k = cycle.index(min(cycle))
        out.append(cycle[k:] + cycle[:k])
    return sorted(out)


MODULES = shipped_modules()


def test_the_analysis_sees_every_layer():
    layers = {layer_of_module(m) for m in MODULES}
    assert layers == {"core", *SUBLAYERS}
    assert "pmnav_bt.testing.doubles" in MODULES and "pmnav_bt.sim.world" in MODULES


@pytest.mark.parametrize("layer", sorted(ALLOWED))
def test_each_layer_imports_only_what_it_may(layer):
    bad = []
    for name, path in MODULES.items():
        if layer_of_module(name) != layer:
            continue
        for line, target in imports(path, name):
            other = layer_of_module(target)
            if other not in (None, "core", layer) and other not in ALLOWED[layer]:
                bad.append(f"{path.relative_to(ROOT)}:{line} imports {target}")
    assert not bad, f"the {layer} layer may not import these:\n" + "\n".join(bad)


@pytest.mark.parametrize("layer", sorted(ALLOWED))
def test_no_layer_imports_itself_in_a_circle(layer):
    """A circle (``config`` imports ``registry``, which imports ``config``) leaves no module
    below the other: neither can be read, tested or reused alone, and a lazy import that
    hides one from Python at import time still counts here."""
    modules = {n: p for n, p in MODULES.items() if layer_of_module(n) == layer}
    cycles = import_cycles(modules)
    assert not cycles, f"import circles in the {layer} layer:\n" + "\n".join(
        " -> ".join([*c, c[0]]) for c in cycles
    )


def test_a_circle_through_a_lazy_import_is_found(tmp_path):
    """The analysis itself: a planted circle, closed by a relative import inside a function."""
    pkg = tmp_path / "pkg"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "sub" / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from pkg.sub.b import helper\n")
    (pkg / "sub" / "b.py").write_text("def helper():\n    from .. import a\n\n    return a\n")
    (pkg / "c.py").write_text("from pkg.a import helper\nfrom pkg.sub import b\n")
    modules = modules_under("pkg", pkg)
    assert set(modules) == {"pkg", "pkg.sub", "pkg.a", "pkg.sub.b", "pkg.c"}
    assert import_cycles(modules) == [["pkg.a", "pkg.sub.b"]]
    (pkg / "sub" / "b.py").write_text("def helper():\n    return 1\n")
    assert import_cycles(modules) == []


def _declared() -> set[str]:
    """Distribution names of the dependencies and of every extra (ROS: the [ros] extra)."""
    reqs = list(PYPROJECT["project"]["dependencies"])
    for extra in PYPROJECT["project"]["optional-dependencies"].values():
        reqs += extra
    # Installed by the Makefile with --no-deps (their metadata names opencv-python).
    reqs += re.findall(r"--no-deps (\S+)", (ROOT / "Makefile").read_text())
    return {re.split(r"[<>=!~\[ ;]", r, maxsplit=1)[0].lower().replace("_", "-") for r in reqs}


def _is_ros(top: str) -> bool:  # rclpy and ROS 2 messages: the [ros] extra / apt
    return top in {"rclpy", "launch", "launch_ros"} or top.endswith(("_msgs", "_interfaces"))


def test_every_third_party_import_is_a_declared_dependency():
    dists = importlib.metadata.packages_distributions()
    declared = _declared()
    missing = set()
    for name, path in MODULES.items():
        for _, target in imports(path, name, fallbacks=False):
            top = target.split(".")[0]
            if top in sys.stdlib_module_names or top == "pmnav_bt" or _is_ros(top):
                continue
            owners = {d.lower().replace("_", "-") for d in dists.get(top, [top])}
            if not owners & declared:
                missing.add(f"{top} (in {path.relative_to(ROOT)})")
    assert not missing, f"imported but not in [project] dependencies: {sorted(missing)}"
