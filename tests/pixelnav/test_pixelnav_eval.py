"""The skill eval's failure reasons: each failed trial says how it failed, counted per method."""

from __future__ import annotations

import pytest

from pmnav_bt.experiments.pixelnav_eval import (
    FAILURES,
    Trial,
    failures,
    format_failures,
    stop_step,
)
from pmnav_bt.pixelnav.dataset import MAX_STEPS


def trial(success, reached, steps, method="pixelnav", dist=4.0):
    return Trial(method, 1, "floor", dist, success, reached, steps, 0.5 if success else 1.4)


def test_each_failure_says_how_it_failed():
    assert trial(True, True, 12).failure == ""
    assert trial(False, False, 16).failure == "stopped short"
    assert trial(False, True, 30).failure == "stopped after passing"
    assert trial(False, True, MAX_STEPS).failure == "no stop, passed"
    assert trial(False, False, MAX_STEPS).failure == "no stop, never near"


def test_failures_are_counted_per_method_and_reason():
    ts = [
        trial(False, False, 16, dist=4.5),
        trial(False, False, 17, dist=3.5),
        trial(True, True, 20),
        trial(False, True, MAX_STEPS, method="geometric"),
        trial(True, True, 20, method="geometric"),
    ]
    rows = {(r["method"], r["failure"]): r for r in failures(ts)}
    assert len(rows) == 2 * len(FAILURES)
    short = rows[("pixelnav", "stopped short")]
    assert (short["n"], short["of"], short["median_goal_m"]) == (2, 3, 4.0)
    assert rows[("geometric", "no stop, passed")]["n"] == 1
    assert rows[("pixelnav", "no stop, passed")]["median_steps"] is None
    text = format_failures(failures(ts))
    line = text.splitlines()[1]
    assert line.startswith("stopped short") and line.split()[-2:] == ["2", "0"]


def test_a_rule_stops_at_its_first_firing_step():
    from pmnav_bt.experiments.pixelnav_eval import sweep

    trace = [(0.01, 9.0, 3.0), (0.04, 5.0, 2.0), (0.2, 1.0, 0.8), (0.5, 0.0, 0.4)]
    assert stop_step(trace, 0.03, None) == 1
    assert stop_step(trace, 0.3, None) == 3
    assert stop_step(trace, 0.3, 1.0) == 2
    assert stop_step(trace, 0.9, None) is None
    rows = {
        (r["stop_threshold"], r["stop_steps"]): r["sr"]
        for r in sweep([trace], [0.03, 0.1, 0.9], [None, 0.0])
    }
    assert rows == {
        (0.03, None): 0.0,  # stops 2 m away
        (0.03, 0.0): 0.0,
        (0.1, None): 1.0,  # stops 0.8 m away
        (0.1, 0.0): 1.0,
        (0.9, None): 0.0,  # never stops
        (0.9, 0.0): 1.0,  # the distance head stops it 0.4 m away
    }


def test_one_stop_free_trace_answers_a_rule_as_the_closed_loop_does():
    torch = pytest.importorskip("torch")
    from pmnav_bt.experiments.pixelnav_eval import evaluate, sweep
    from pmnav_bt.pixelnav.model import TINY, PixelNavNet
    from pmnav_bt.pixelnav.policy import PixelNavPolicy

    torch.manual_seed(0)
    policy = PixelNavPolicy(PixelNavNet(TINY))
    traces: list = []
    evaluate(policy, 1, 3, progress=False, validation=True, traces=traces)
    probs = sorted(p for tr in traces for p, _, _ in tr)
    threshold = probs[len(probs) * 9 // 10]  # fires part-way along some traces
    policy.stop_threshold = threshold
    closed = [t for t in evaluate(policy, 1, 3, progress=False, validation=True)]
    closed = [t for t in closed if t.method == "pixelnav"]
    at = [stop_step(tr, threshold, None) for tr in traces]
    assert any(i is not None and i > 0 for i in at)  # a stop part-way: the test bites
    assert [t.steps for t in closed] == [MAX_STEPS if i is None else i + 1 for i in at]
    sr = sweep(traces, [threshold], [None])[0]["sr"]
    assert sr == sum(t.success for t in closed) / len(closed)


def test_calibrate_names_a_bad_rule_in_one_line(capsys, tmp_path):
    from pmnav_bt.experiments.cli import main

    for argv in (["--thresholds", "0.1,lots"], ["--steps", "off,nan"]):
        with pytest.raises(SystemExit) as info:
            main(["pixelnav", "calibrate", "--out", str(tmp_path), *argv])
        err = capsys.readouterr().err.strip()
        assert info.value.code != 0 and len(err.splitlines()) == 1
        assert argv[0] in err and "Traceback" not in err
