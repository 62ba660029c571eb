"""The evaluation's report: each variant's failure codes and wall times, the oracle named."""

from __future__ import annotations

from pmnav_bt.config import load_config
from pmnav_bt.eval.metrics import EpisodeResult
from pmnav_bt.experiments.evaluation import comparison_markdown, failure_code, variant_configs
from pmnav_bt.registry import grounder_label


def _result(ok: bool, reason: str | None, wall: float, hits=0, people=0) -> EpisodeResult:
    return EpisodeResult("e", "easy", ok, 1.0 if ok else 0.0, 5.0, 10, collisions=hits,
                         wall_time=wall, failure_reason=reason, people_contacts=people)  # fmt: skip


def test_the_default_grounder_is_real_and_the_oracle_is_labelled():
    cfgs = variant_configs(load_config(), ["pmnav", "coarse_only", "pmnav_oracle"])
    assert [c.grounder.backend for c in cfgs.values()] == ["ocr", "ocr", "sim_gt"]
    assert grounder_label("sim_gt") == "sim_gt (oracle)" and grounder_label("ocr") == "ocr"


def test_the_report_lists_failure_codes_wall_times_and_contacts_per_variant():
    rs = {
        "pmnav": [
            _result(True, None, 10.0),
            _result(False, "BUDGET_EXCEEDED: 500 actions", 30.0, hits=2, people=1),
            _result(False, "LOCALIZATION_FAILED: 0 signs read", 20.0),
        ],
        "pmnav_oracle": [_result(True, None, 5.0)],
    }
    md = comparison_markdown(rs)
    assert "| easy | 3 | 33.3 |" in md
    assert (
        "- PM-Nav: failures: BUDGET_EXCEEDED 1, LOCALIZATION_FAILED 1; "
        "episode wall time mean / p95: 20.0 s / 29.0 s; "
        "collisions: 2 (66.7 per 100 episodes); people contacts: 1" in md
    )
    assert "- PM-Nav (oracle: simulator labels): failures: none" in md
    assert failure_code("stopped 2.3 m from the door") == "OTHER"
