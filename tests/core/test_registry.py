"""The back-end registry: one factory for the simulator and the robot, typed config names,
one-line refusals, and ``pmnav backends``."""

from __future__ import annotations

import pytest

from pmnav_bt.backends import build_backends
from pmnav_bt.cli import main
from pmnav_bt.config import load_config
from pmnav_bt.errors import BackendError, ConfigError
from pmnav_bt.perception.coarse import DetectorCoarseDirection
from pmnav_bt.perception.grounders.ground_truth import GroundTruthGrounder
from pmnav_bt.perception.refiners.geometric import GeometricRefiner
from pmnav_bt.planning.graph_planner import GraphPlanner
from pmnav_bt.registry import (
    GROUNDERS,
    ORACLE_READING,
    REGISTRIES,
    BackendSpec,
    GrounderSpec,
    grounder_label,
)
from pmnav_bt.seams import CoarseDirection, Grounder, Planner, Refiner


def test_a_config_builds_every_seam_from_the_registry(fig2_map):
    cfg = load_config(
        overrides=["grounder.backend=sim_gt", "grounder.miss_rate=0.25", "planner.max_gap=6"]
    )
    b = build_backends(cfg, fig2_map, on_robot=False, seed=3)
    assert isinstance(b.grounder, GroundTruthGrounder) and isinstance(b.grounder, Grounder)
    assert (b.grounder.miss_rate, b.grounder.seed) == (0.25, 3)
    assert isinstance(b.coarse, DetectorCoarseDirection) and isinstance(b.coarse, CoarseDirection)
    assert b.coarse.grounder is b.grounder  # the detector grounds with the run's grounder
    assert isinstance(b.refiner, GeometricRefiner) and isinstance(b.refiner, Refiner)
    assert b.refiner.gives_range
    assert isinstance(b.planner, GraphPlanner) and isinstance(b.planner, Planner)
    assert b.planner.max_gap == 6


def test_a_simulator_only_grounder_is_refused_on_a_robot_in_one_line(fig2_map):
    with pytest.raises(BackendError) as info:
        build_backends(load_config(overrides=["grounder.backend=sim_gt"]), fig2_map, on_robot=True)
    msg = str(info.value)
    assert "\n" not in msg and "grounder.backend 'sim_gt'" in msg and "robot" in msg


def test_an_unknown_back_end_lists_the_registered_ones():
    with pytest.raises(ConfigError, match="unknown back end 'orc'.*registered: sim_gt, ocr"):
        load_config(overrides=["grounder.backend=orc"])


def _scripted(deps):
    from pmnav_bt.testing.doubles import ScriptedGrounder

    return ScriptedGrounder(deps.pm)


def test_a_new_back_end_registers_by_name_and_runs_on_a_robot(fig2_map):
    with pytest.raises(TypeError, match="GrounderSpec"):  # a grounder says how it reads
        GROUNDERS.register(BackendSpec("scripted", f"{__name__}:_scripted", "test double"))
    spec = GrounderSpec("scripted", f"{__name__}:_scripted", "test double", reading=ORACLE_READING)
    GROUNDERS.register(spec)
    try:
        cfg = load_config(overrides=["grounder.backend=scripted"])
        b = build_backends(cfg, fig2_map, on_robot=True)
        assert type(b.grounder).__name__ == "ScriptedGrounder" and b.coarse.grounder is b.grounder
    finally:
        GROUNDERS._specs.pop("scripted")


def test_pmnav_backends_lists_every_registered_back_end(capsys):
    with pytest.raises(SystemExit) as info:
        main(["backends"])
    out = capsys.readouterr().out
    assert (info.value.code or 0) == 0
    for seam, registry in REGISTRIES.items():
        for name in registry.names():
            line = next(x for x in out.splitlines() if x.split()[:2] == [f"{seam}.backend", name])
            assert registry.spec(name).summary in line
    assert "[sim only, oracle]" in next(x for x in out.splitlines() if " sim_gt " in x)
    assert "[default]" in next(x for x in out.splitlines() if " ocr " in x)


def test_the_oracle_label_follows_the_declared_flag_not_the_simulator_labels():
    assert grounder_label("sim_gt") == "sim_gt (oracle)" and grounder_label("ocr") == "ocr"
    specs = [
        GrounderSpec("fiducials", f"{__name__}:_scripted", "", reading=ORACLE_READING, oracle=True),
        GrounderSpec("sim_ocr", f"{__name__}:_scripted", "", needs_sim_labels=True),
    ]
    for spec in specs:
        GROUNDERS.register(spec)
    try:
        assert grounder_label("fiducials") == "fiducials (oracle)"
        assert grounder_label("sim_ocr") == "sim_ocr"
    finally:
        for spec in specs:
            GROUNDERS._specs.pop(spec.name)
