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


def qualified(t: tuple[str, str]) -> str:
    """A level and a name as a person might join them: 'L2/x' or 'x on L2'."""
    level, name = t
    return f"{level}/{name}" if len(name) % 2 else f"{name} on {level}"


@FUZZ
@given(
    goal=st.one_of(
        st.text(max_size=60),
        st.tuples(st.sampled_from(["L1", "l2", "L9", "", " "]), st.text(max_size=20)).map(
            qualified
        ),
    ),
    level=st.sampled_from(["L1", "L2", "l2", "L9", "L1/x", "../L1"]),
)
def test_plan_across_levels_any_goal_and_level(capsys, goal, level):
    """A site's goal (qualified or not) and start level as anyone may type them."""
    TRIED["CLI: plan across levels, any goal"] += 1
    if goal.startswith("-"):
        goal = " " + goal
    argv = ["plan", "hospital_2l", "--from", "start", "--to", goal, "--start-level", level]
    code, out, err = pmnav_cli(capsys, *argv)
    if code != 0:
        assert code == 2
        one_line(err, "pmnav: error:")
    else:
        assert out.startswith("Plan in hospital_2l")


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


# -- issue 42: the generators that would have found its examples -------------------------

DIGITS = st.builds(
    lambda lead, n: lead + "9" * n, st.sampled_from(["", "1", "-1", "-"]), st.integers(9, 5000)
)  # from 10 digits (no segment, no building has such a number) past int()'s 4300 digits


@FUZZ
@given(
    spec=st.one_of(
        DIGITS.map(lambda d: f"seg{d.lstrip('-')}"),
        st.tuples(DIGITS, st.sampled_from(["", "(start-end1)", "(a-b)"])).map(
            lambda t: f"seg{t[0].lstrip('-')}{t[1]}"
        ),
        st.tuples(DIGITS, DIGITS).map(",".join),
        st.tuples(DIGITS, DIGITS, DIGITS).map(",".join),
    ),
    command=st.sampled_from(["plan", "sim run"]),
)
def test_huge_numbers_inside_pose_and_segment_specs(capsys, tmp_path, spec, command):
    TRIED["CLI: huge numbers in --from/--start specs"] += 1
    if spec.startswith("-"):
        spec = " " + spec
    if command == "plan":
        argv = ["plan", "straight_office", "--from", spec, "--to", "room1"]
    else:
        argv = ["sim", "run", "--goal", "room1", "--start", spec, "--out", tmp_path / "o"]
    code, _, err = pmnav_cli(capsys, *argv)
    assert code == 2  # x and y of 10 digits and more are never in a corridor
    one_line(err, "pmnav: error:")


NOTHING = st.text(alphabet=" ,\t", min_size=1, max_size=8)  # a list that names no item


@FUZZ
@given(
    where=st.sampled_from(
        [
            ("sim", "eval", "--variants"),
            ("sim", "eval", "--building"),
            ("sim", "eval", "--tier"),
            ("sim", "table3", "--building"),
            ("report", "--variants"),
            ("report", "--building"),
            ("report", "--table3-building"),
            ("plan", "eval", "--inputs"),
        ]
    ),
    text=NOTHING,
)
def test_empty_lists_in_options(capsys, tmp_path, where, text):
    TRIED["CLI: comma lists naming nothing"] += 1
    *command, option = where
    out = tmp_path / f"o{TRIED['CLI: comma lists naming nothing']}"
    code, _, err = pmnav_cli(capsys, *command, option, text, "--out", out)
    assert code == 2
    one_line(err, option)
    assert not [p for p in out.rglob("*") if p.is_file()]  # nothing written


def _value_options():
    """(command words, option) for every option of every pmnav command that takes a value."""
    import typer

    from pmnav_bt.experiments.cli import app

    found = []

    def walk(cmd, words):
        for name, sub in sorted(getattr(cmd, "commands", {}).items()):
            walk(sub, [*words, name])
        for p in cmd.params:
            if p.param_type_name == "option" and not p.is_flag and p.nargs == 1:
                found.append((tuple(words), max(p.opts, key=len)))
            elif p.param_type_name == "argument":
                found.append((tuple(words), None))

    walk(typer.main.get_command(app), [])
    return sorted(set(found), key=str)


VALUE_OPTIONS = _value_options()


@pytest.mark.parametrize("form", ["separate", "equals"])
@pytest.mark.parametrize(
    "words, option", VALUE_OPTIONS, ids=[f"{' '.join(w)} {o or 'ARG'}" for w, o in VALUE_OPTIONS]
)
def test_empty_values_everywhere(capsys, tmp_path, monkeypatch, words, option, form):
    """No option or argument of any command takes an empty value (``--out ''`` was the
    current folder): one line, and nothing written where the command ran."""
    if form == "equals" and not (option or "").startswith("--"):
        pytest.skip("only a long option has a --name= form")
    TRIED["CLI: empty values, every option"] += 1
    monkeypatch.chdir(tmp_path)
    given = [option, ""] if form == "separate" and option else [f"{option}="] if option else [""]
    code, _, err = pmnav_cli(capsys, *words, *given)
    assert code == 2
    one_line(err, "empty")
    assert list(tmp_path.iterdir()) == []


RESULT_MARKS = {
    "sim eval": ["results.jsonl", "results.json", "results.md", "overwriting/results.jsonl"],
    "sim table3": ["results.jsonl", "results.json", "results.md", "overwriting/results.md"],
    "report": ["eval/results.jsonl", "table3/results.jsonl", "report.md",
               "overwriting/eval/results.jsonl"],
}  # fmt: skip


@FUZZ
@given(
    command=st.sampled_from(sorted(RESULT_MARKS)),
    picks=st.lists(st.integers(0, 3), min_size=1, max_size=4, unique=True),
    texts=st.lists(st.binary(max_size=40), min_size=4, max_size=4),
    resume=st.booleans(),
)
def test_folders_holding_other_results(capsys, tmp_path, command, picks, texts, resume):
    """A folder holding results (any of them, any content) is refused whole, before any
    episode runs: without --resume always; with --resume when there is no store to go on
    from, or the store's rows are not this run's."""
    TRIED["CLI: folders holding other results"] += 1
    out = tmp_path / f"o{TRIED['CLI: folders holding other results']}"
    files = {RESULT_MARKS[command][i]: texts[i] for i in picks}
    for name, data in files.items():
        (out / name).parent.mkdir(parents=True, exist_ok=True)
        (out / name).write_bytes(data)
    argv = [*command.split(), "-n", "1", "--building", "straight_office", "--out", out]
    if command == "report":
        argv += ["--no-table3", "--trajectories", "0"]
    store = RESULT_MARKS[command][0]
    if resume and (store in files or f"overwriting/{store}" in files):
        return  # --resume goes on from a store: the result store judges its rows
    code, _, err = pmnav_cli(capsys, *argv, *(["--resume"] if resume else []))
    assert code == 2
    one_line(err, "pmnav: error:", "--overwrite")
    assert {n: (out / n).read_bytes() for n in files} == files  # untouched
