"""``pmnav report --from`` renders report.md from a small fixture of results: Tables 1, 3
and 4 beside the paper's numbers, each variant's grounder, the oracle labelled, failure
codes, charts, config and commit; rows made under another config are left out."""

from __future__ import annotations

from dataclasses import asdict

import pytest

from pmnav_bt.config import load_config
from pmnav_bt.eval.metrics import EpisodeResult
from pmnav_bt.experiments.cli import main
from pmnav_bt.experiments.localization_study import LocResult, LocStart, start_key
from pmnav_bt.experiments.report import _write_meta, pick_trajectories
from pmnav_bt.experiments.runstore import Expected, ResultStore, record_key
from pmnav_bt.experiments.stored_run import STUDY
from pmnav_bt.experiments.variants import ORACLE_LABEL, config_hash, variant_configs


def _result(eid, tier, ok, spl, reason=None, error=None, hits=0, people=0):
    return EpisodeResult(
        episode_id=eid,
        tier=tier,
        success=ok,
        spl=spl,
        path_length=5.0,
        steps=10,
        failure_reason=reason,
        building="b1" if eid.endswith("0") else "b2",
        route_length=4.0,
        error=error,
        collisions=hits,
        people_contacts=people,
    )


FIXTURE = {
    "pmnav": [
        _result("e0", "easy", True, 0.8),
        _result("e1", "easy", True, 0.6),
        _result("h0", "hard", False, 0.0, "TARGET_NOT_FOUND: room9 not seen", hits=1, people=1),
    ],
    "coarse_only": [
        _result("e0", "easy", False, 0.0, "STOPPED_AWAY: stopped 1.7 m from the door"),
        _result("e1", "easy", True, 0.5),
        _result("h0", "hard", False, 0.0, error="RuntimeError: boom"),
    ],
    "pmnav_oracle": [
        _result("e0", "easy", True, 0.9),
        _result("e1", "easy", True, 0.9),
        _result("h0", "hard", True, 0.7),
    ],
}


@pytest.fixture
def folder(tmp_path):
    base = load_config(None, ["grounder.backend=ocr"])
    configs = variant_configs(base, list(FIXTURE))
    out = tmp_path / "report"
    (out / "eval").mkdir(parents=True)
    _write_meta(
        out,
        base,
        configs,
        {"building": "b1,b2", "tier": "easy,hard", "n": 2, "seed": 0},
        {"building": "b1", "n": 2, "grounder": "ocr"},
        total=9,
    )
    expected = [
        Expected(record_key(n, r.episode_id), n, "x", config_hash(configs[n]))
        for n, rs in FIXTURE.items()
        for r in rs
    ]
    with ResultStore(out / "eval" / "results.jsonl", expected, resume=False) as store:
        for n, rs in FIXTURE.items():
            for r in rs:
                store.write(record_key(n, r.episode_id), r.to_dict())
    with open(out / "eval" / "results.jsonl", "a") as f:  # another config's row, a torn tail
        f.write('{"variant": "pmnav", "key": "pmnav/zz", "config_sha": "old", "episode_id": ')
    starts = [LocStart("b1", 0, 0, 0, d, 3, i) for i, d in enumerate(["redundant", "scarce"])]
    rows = [LocResult(s, s.density == "redundant", 1, 0.1, 1.0, 0.0, None, 1.0) for s in starts]
    exp = [Expected(record_key(STUDY, start_key(s)), STUDY, "x", "c") for s in starts]
    (out / "table3").mkdir()
    with ResultStore(out / "table3" / "results.jsonl", exp, resume=False) as store:
        for s, r in zip(starts, rows, strict=True):
            store.write(record_key(STUDY, start_key(s)), {**asdict(r), "start": asdict(s)})
    return out


def test_report_from_results_has_the_three_tables_beside_the_paper(folder, capsys):
    with pytest.raises(SystemExit) as info:
        main(["report", "--from", str(folder)])
    assert (info.value.code or 0) == 0
    md = (folder / "report.md").read_text()
    # Table 1: ours (errors left out of SR/SPL), then the paper's rows
    assert "| PM-Nav | 100.0 | 70.0 | 0.0 | 0.0 | 3 |" in md
    assert "| coarse-only | 50.0 | 25.0 | - | - | 3 |" in md
    assert "| *paper: SG-Nav* | 12.0 | 5.0 | 0.0 | 0.0 | |" in md
    assert "| *paper: PM-Nav* | 88.0 | 77.4 | 46.0 | 36.4 | |" in md
    table1 = md.split("## Table 1")[1].split("## Table 3")[0]
    assert ORACLE_LABEL not in table1  # the oracle is a bound in Table 4, not a method
    # Table 3 from the study, beside the paper
    assert "| redundant | 1 | 100.0 | 100.0 |" in md and "| 93.8 | 90.4 |" in md
    # Table 4: coarse vs fine and the labelled oracle, beside the paper's coarse and fine
    assert f"PM-Nav ({ORACLE_LABEL}) SR" in md
    assert "| hard | 0.0 | 0.0 | - | - | 100.0 | 70.0 | 0.0 | 0.0 | 46.0 | 36.4 |" in md
    # each variant's grounder, stated
    assert "| pmnav | PM-Nav | pmnav | ocr |" in md
    assert "| pmnav_oracle | PM-Nav (oracle: simulator labels) | pmnav | sim_gt |" in md
    # failure codes per variant, an errored run counted as ERROR
    assert "| coarse-only | 1 | 1 | 0 |" in md and "| ERROR | STOPPED_AWAY |" in md
    # contacts per variant: collisions (per 100 episodes that ran) and people
    assert "| PM-Nav | 3 | 1 | 33.3 | 1 |" in md and "| coarse-only | 2 | 0 | 0.0 | 0 |" in md
    # the configuration and the commit
    assert "grounder:\n    backend: ocr" in md and "Commit `" in md
    for png in ("sr_spl.png", "failures.png"):
        data = (folder / "plots" / png).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000
        assert f"(plots/{png})" in md
    assert "PARTIAL" not in md


def test_a_folder_without_results_metadata_is_one_clear_line(tmp_path, capsys):
    with pytest.raises(SystemExit) as info:
        main(["report", "--from", str(tmp_path)])
    assert info.value.code == 2
    err = capsys.readouterr().err.strip()
    assert "meta.json" in err and len(err.splitlines()) == 1


def test_trajectories_pick_a_hard_success_a_failure_and_the_same_episode_elsewhere():
    picks = pick_trajectories(FIXTURE, 3)
    assert picks == [("pmnav", "e0"), ("pmnav", "h0"), ("coarse_only", "e0")]
