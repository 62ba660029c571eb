"""The real grounders come from the registry, on the robot as in the simulator."""

from __future__ import annotations

import pytest

from pmnav_bt.backends import BackendDeps
from pmnav_bt.config import load_config
from pmnav_bt.errors import BackendError
from pmnav_bt.registry import GROUNDERS
from pmnav_bt.seams import Grounder


def test_ocr_builds_on_a_robot_and_reads_no_labels(fig2_map):
    pytest.importorskip("rapidocr_onnxruntime")
    cfg = load_config(None, ["grounder.backend=ocr", "grounder.door_side=right"])
    g = GROUNDERS.build("ocr", BackendDeps(config=cfg, pm=fig2_map, on_robot=True))
    assert isinstance(g, Grounder) and g.needs_sim_labels is False
    assert g.layout.default_side == "right"
    assert not GROUNDERS.spec("ocr").needs_sim_labels


def test_gdino_sam_without_weights_is_one_clear_error(fig2_map, tmp_path):
    cfg = load_config(None, ["grounder.backend=gdino_sam", f"grounder.gdino_path={tmp_path}"])
    with pytest.raises(BackendError, match=r"grounder.gdino_path: no GroundingDINO model"):
        GROUNDERS.build("gdino_sam", BackendDeps(config=cfg, pm=fig2_map, on_robot=True))
