"""Generated bad command-line values: every one is a single line and a non-zero exit.

Runs ``pmnav`` in this process (fuzzkit.pmnav_cli). The values are chosen invalid (out of
range, not finite, not numbers), so no command gets as far as running episodes.
"""

from __future__ import annotations

import pytest
from fuzzkit import TRIED, one_line, pmnav_cli
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

pytestmark = pytest.mark.timeout(120)  # bounded time, whatever regresses

FUZZ = settings(
    max_examples=100,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)

NOT_A_NUMBER = st.one_of(
    st.sampled_from(["nan", "inf", "-inf", "1e400", "9" * 400, "", "x", "1,2", "0x10", "--"]),
    st.text(alphabet=st.characters(blacklist_categories=["Nd", "Cs"]), min_size=1, max_size=20),
)


@FUZZ
@given(
    spec=st.one_of(
        st.text(max_size=60),
        st.lists(st.one_of(NOT_A_NUMBER, st.floats().map(repr)), min_size=2, max_size=3).map(
            ",".join
        ),
    )
)
def test_plan_start_any_text(capsys, spec):
    TRIED["CLI: plan --from any text"] += 1
    if spec.startswith("-"):
        spec = " " + spec  # an option-like value is click's business, not ours
    code, _, err = pmnav_cli(capsys, "plan", "straight_office", "--from", spec, "--to", "room1")
    if code != 0:
        assert code == 2
        one_line(err, "pmnav: error:")


@FUZZ
@given(
    option=st.sampled_from(["-n", "--jobs", "--seed"]),
    value=st.one_of(
        st.integers(max_value=-1),
        st.integers(min_value=10_001, max_value=10**40),
        NOT_A_NUMBER,
    ),
)
def test_eval_numbers(capsys, option, value):
    TRIED["CLI: sim eval -n/--jobs/--seed"] += 1
    if option == "--seed" and isinstance(value, int) and 0 <= value < 2**63:
        value = -1 - value  # a valid seed would start a run
    text = str(value)
    if text.startswith("-") and not text.lstrip("-").isdigit():
        text = " " + text
    code, _, err = pmnav_cli(capsys, "sim", "eval", option, text, "--out", "/nonexistent/x/y")
    assert code != 0
    one_line(err, "pmnav: error:")


@FUZZ
@given(
    pose=st.lists(
        st.one_of(NOT_A_NUMBER, st.floats(min_value=1001).map(repr)), min_size=1, max_size=4
    ).map(",".join)
)
def test_show_pose(capsys, pose, tmp_path):
    TRIED["CLI: sim show --pose"] += 1
    code, _, err = pmnav_cli(
        capsys, "sim", "show", "straight_office", "--pose", " " + pose, "--out", tmp_path
    )
    assert code == 2
    one_line(err, "--pose")


@pytest.mark.parametrize("value", ["far", "", "STACK", "9.5"])
def test_table3_class_range_is_stack_or_map(capsys, tmp_path, value):
    TRIED["CLI: sim table3 --class-range"] += 1
    code, _, err = pmnav_cli(
        capsys, "sim", "table3", "--class-range", value, "--out", tmp_path / "t3"
    )
    assert code != 0
    one_line(err, "pmnav: error:")
    assert "--class-range" in err and not (tmp_path / "t3" / "results.jsonl").exists()
