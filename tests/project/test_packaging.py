"""The wheel carries every package and the built-in buildings (a non-editable install
once lacked pmnav_bt.perception)."""

from __future__ import annotations

from pathlib import Path

import pytest

tomllib = pytest.importorskip("tomllib")  # Python 3.11+

ROOT = Path(__file__).resolve().parents[2]


def test_every_package_folder_is_listed_in_pyproject():
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(cfg["packages"])
    dirs = cfg["package-dir"]
    found = set()
    for name, folder in dirs.items():
        for init in (ROOT / folder).rglob("__init__.py"):
            rel = init.parent.relative_to(ROOT / folder)
            found.add(".".join([name, *rel.parts]))
    assert found <= listed, f"missing from [tool.setuptools] packages: {sorted(found - listed)}"


def test_builtin_buildings_are_package_data():
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    assert "buildings/*.yaml" in cfg["package-data"]["pmnav_bt.data"]
    assert list((ROOT / "pmnav_bt" / "data" / "buildings").glob("*.yaml"))


def test_builtin_sites_and_their_levels_are_package_data():
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    data = cfg["package-data"]["pmnav_bt.data"]
    assert "sites/*.yaml" in data and "sites/*/*.yaml" in data
    assert list((ROOT / "pmnav_bt" / "data" / "sites").glob("*/*.yaml"))


def test_every_data_file_is_package_data():
    """Each file the core reads from pmnav_bt/data/ ships in the wheel (the sign ranges
    once did not)."""
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    data = ROOT / "pmnav_bt" / "data"
    shipped = {f for glob in cfg["package-data"]["pmnav_bt.data"] for f in data.glob(glob)}
    files = {
        f
        for f in data.rglob("*")
        if f.is_file() and f.suffix != ".py" and "__pycache__" not in f.parts
    }
    missing = sorted(str(f.relative_to(data)) for f in files - shipped)
    assert not missing, f"missing from [tool.setuptools.package-data] pmnav_bt.data: {missing}"


def test_the_core_imports_no_tree_simulator_or_ros_at_import_time():
    import subprocess
    import sys

    core = sorted(
        "pmnav_bt." + ".".join(p.relative_to(ROOT / "pmnav_bt").with_suffix("").parts)
        for p in (ROOT / "pmnav_bt").rglob("*.py")
        if p.name != "__init__.py"
    )
    code = (
        "import importlib, sys\n"
        f"for m in {core!r}: importlib.import_module(m)\n"
        "print(' '.join(sorted({'py_trees', 'pybullet', 'rclpy'} & set(sys.modules))))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "", f"the core imported {out.stdout.strip()}"
