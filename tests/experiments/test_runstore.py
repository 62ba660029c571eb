"""results.jsonl as a resumable store: finished keys skipped, another config refused in one
line, a torn last line (a kill mid-write) tolerated and cut off, damage elsewhere refused;
named variants; progress lines with rate and ETA."""

from __future__ import annotations

import io
import json

import pytest

from pmnav_bt.config import load_config
from pmnav_bt.experiments.progress import LogProgress
from pmnav_bt.experiments.runstore import Expected, ResultStore, ResumeError, read_rows
from pmnav_bt.experiments.variants import (
    ORACLE_LABEL,
    VARIANTS,
    Variant,
    config_hash,
    variant_configs,
    variant_title,
)


def _expected(keys, config="c1", variant="v"):
    return [Expected(f"{variant}/{k}", variant, f"item-{k}", config) for k in keys]


def _fill(path, keys, config="c1"):
    with ResultStore(path, _expected(keys, config), resume=False) as store:
        for k in keys:
            store.write(f"v/{k}", {"episode_id": k, "success": True})


def test_resume_keeps_finished_keys_and_runs_only_the_rest(tmp_path):
    path = tmp_path / "results.jsonl"
    _fill(path, ["a", "b"])
    with ResultStore(path, _expected(["a", "b", "c", "d"]), resume=True) as store:
        assert set(store.done) == {"v/a", "v/b"}
        assert store.todo(["v/a", "v/b", "v/c", "v/d"]) == ["v/c", "v/d"]
        store.write("v/c", {"episode_id": "c"})
    rows, _ = read_rows(path)
    assert [r["key"] for r in rows] == ["v/a", "v/b", "v/c"]  # appended, nothing rewritten


def test_without_resume_the_file_starts_afresh(tmp_path):
    path = tmp_path / "results.jsonl"
    _fill(path, ["a", "b"])
    with ResultStore(path, _expected(["a"]), resume=False) as store:
        assert store.done == {}
    assert path.read_text() == ""


def test_resume_refuses_results_made_under_another_config(tmp_path):
    path = tmp_path / "results.jsonl"
    _fill(path, ["a"], config="c1")
    with pytest.raises(ResumeError) as info:
        ResultStore(path, _expected(["a", "b"], config="c2"), resume=True)
    msg = str(info.value)
    assert "another config" in msg and "c1" in msg and "c2" in msg and "\n" not in msg


def test_resume_refuses_another_episode_under_the_same_key(tmp_path):
    path = tmp_path / "results.jsonl"
    _fill(path, ["a"])
    other = [Expected("v/a", "v", "item-CHANGED", "c1")]
    with pytest.raises(ResumeError, match="different episode"):
        ResultStore(path, other, resume=True)


def test_a_torn_last_line_is_dropped_and_cut_off_before_appending(tmp_path):
    path = tmp_path / "results.jsonl"
    _fill(path, ["a", "b"])
    whole = path.read_bytes()
    path.write_bytes(whole + b'{"variant": "v", "key": "v/c", "suc')  # killed mid-write
    with ResultStore(path, _expected(["a", "b", "c"]), resume=True) as store:
        assert set(store.done) == {"v/a", "v/b"}
        store.write("v/c", {"episode_id": "c"})
    lines = path.read_text().splitlines()
    assert [json.loads(x)["key"] for x in lines] == ["v/a", "v/b", "v/c"]


def test_a_whole_last_row_without_its_newline_is_kept(tmp_path):
    path = tmp_path / "results.jsonl"
    _fill(path, ["a", "b"])
    path.write_bytes(path.read_bytes().rstrip(b"\n"))
    with ResultStore(path, _expected(["a", "b", "c"]), resume=True) as store:
        assert set(store.done) == {"v/a", "v/b"}
        store.write("v/c", {"episode_id": "c"})
    assert len(read_rows(path)[0]) == 3


def test_a_broken_line_before_the_last_is_damage_not_a_kill(tmp_path):
    path = tmp_path / "results.jsonl"
    _fill(path, ["a", "b"])
    lines = path.read_text().splitlines()
    path.write_text(lines[0][:10] + "\n" + lines[1] + "\n")
    with pytest.raises(ResumeError, match="line 1"):
        ResultStore(path, _expected(["a", "b"]), resume=True)


def test_variants_apply_their_overrides_and_the_oracle_says_so():
    base = load_config(None, ["grounder.backend=ocr"])
    configs = variant_configs(base, ["pmnav", "coarse_only", "pmnav_oracle"])
    assert configs["pmnav"].grounder.backend == "ocr"  # the run's grounder, not a default
    assert configs["coarse_only"].tree.variant == "coarse_only"
    assert configs["pmnav_oracle"].grounder.backend == "sim_gt"
    assert ORACLE_LABEL in variant_title("pmnav_oracle") and VARIANTS["pmnav_oracle"].oracle
    assert len({config_hash(c) for c in configs.values()}) == 3
    assert config_hash(load_config(None, ["sim.width=160"])) != config_hash(load_config())


def test_a_variant_is_an_oracle_exactly_when_its_grounder_declares_itself_one():
    real = Variant("mine", "mine", (("grounder.backend", "ocr"),))
    truth = Variant("mine_gt", "mine", (("grounder.backend", "sim_gt"),))
    assert not real.oracle and ORACLE_LABEL not in real.title
    assert truth.oracle and ORACLE_LABEL in truth.title
    assert not VARIANTS["pmnav"].oracle  # no grounder of its own: the run's, stated per row


def test_an_unknown_variant_names_the_known_ones():
    with pytest.raises(Exception, match="pmnav_oracle"):
        variant_configs(load_config(), ["nope"])


def test_log_progress_prints_rate_and_eta_at_most_every_interval_for_fast_runs():
    now = [0.0]
    out = io.StringIO()
    log = LogProgress(100, already=20, interval=30.0, stream=out, clock=lambda: now[0])
    for k in range(21, 101):
        now[0] += 1.0  # one run a second: fast
        log(k)
    lines = out.getvalue().splitlines()
    assert lines[0].startswith("21/100 episodes; 3600/h; ETA 1m19s")
    assert lines[-1].startswith("100/100 episodes; 3600/h; ETA 0m00s")
    assert 3 <= len(lines) <= 5  # the first, one per ~30 s, the last


def test_log_progress_prints_every_run_when_runs_are_slow():
    now = [0.0]
    out = io.StringIO()
    log = LogProgress(5, stream=out, clock=lambda: now[0])
    for k in range(1, 6):
        now[0] += 10.0
        log(k)
    assert len(out.getvalue().splitlines()) == 5
