"""The evaluation as a run that survives: results stream to ``results.jsonl`` (keyed,
resumable), Ctrl-C/SIGTERM keeps them and writes a partial table, progress shows rate
and ETA. Shared by ``pmnav sim eval`` and ``pmnav report``."""

from __future__ import annotations

import sys
from collections.abc import Callable
from dataclasses import dataclass, fields
from pathlib import Path

from pmnav_bt.config import Config
from pmnav_bt.eval.metrics import EpisodeResult
from pmnav_bt.experiments.runstore import Expected, ResultStore, record_key, stable_hash
from pmnav_bt.experiments.variants import config_hash

_RESULT_FIELDS = {f.name for f in fields(EpisodeResult)}


def episode_sha(episode) -> str:
    """A hash of what defines an episode (its building by content, not by path)."""
    d = episode.to_dict()
    d.pop("building_path", None)
    return stable_hash(d)


def result_of(row: dict) -> EpisodeResult:
    """An EpisodeResult from a results.jsonl row (the store's own fields dropped)."""
    return EpisodeResult.from_dict({k: v for k, v in row.items() if k in _RESULT_FIELDS})


@dataclass(frozen=True)
class StoredRun:
    """Where a stored run writes (``out``: its ``results.jsonl``, kept between sessions) and
    how it runs: ``jobs`` worker processes (or a Ray cluster at ``ray``), ``resume`` the
    runs already in ``out``, progress lines to ``echo``."""

    out: Path
    jobs: int = 1
    ray: str | None = None
    resume: bool = False
    echo: Callable[[str], None] = print


@dataclass
class RunOutcome:
    results: dict[str, list[EpisodeResult]]
    new: int  # runs finished in this session
    resumed: int  # runs found done on disk
    total: int
    stopped_by: str | None = None  # SIGINT or SIGTERM when interrupted
    exit_code: int = 0


def run_stored_evaluation(episodes: list, configs: dict[str, Config], run: StoredRun) -> RunOutcome:
    """Run (or resume) the evaluation into ``run.out/results.jsonl``; on SIGINT/SIGTERM
    return what finished with ``stopped_by`` set (the caller writes the partial table)."""
    from pmnav_bt.experiments.evaluation import evaluate
    from pmnav_bt.experiments.progress import LogProgress, bar_columns
    from pmnav_bt.interrupts import Interrupted, stop_signals

    out, jobs, ray, resume, echo = run.out, run.jobs, run.ray, run.resume, run.echo
    shas = {e.id: episode_sha(e) for e in episodes}
    expected = [
        Expected(record_key(n, e.id), n, shas[e.id], config_hash(c))
        for n, c in configs.items()
        for e in episodes
    ]
    total = len(expected)
    finished: dict[str, list[EpisodeResult]] = {}
    with ResultStore(out / "results.jsonl", expected, resume) as store:
        done = {(row["variant"], row["episode_id"]): result_of(row) for row in store.done.values()}
        if resume:
            echo(f"resuming {out / 'results.jsonl'}: {len(done)} of {total} runs done")
            if store.duplicates:
                echo(f"note: {store.duplicates} duplicate rows ignored (first kept)")

        def save(name: str, r: EpisodeResult) -> None:
            store.write(record_key(name, r.episode_id), r.to_dict())

        outcome = RunOutcome(finished, 0, len(done), total)
        with stop_signals():
            try:
                if sys.stderr.isatty():
                    from rich.progress import Progress

                    with Progress(*bar_columns(), transient=False) as bar:
                        task = bar.add_task("episodes", total=total, completed=len(done), rate="")
                        log = LogProgress(total, len(done))

                        def tick(name: str, n: int, _total: int) -> None:
                            rate = log.line(n).split("; ")[1:2]
                            bar.update(task, completed=n, rate=rate[0] if rate else "")

                        evaluate(episodes, configs, jobs, tick, save, finished, ray=ray, done=done)
                else:
                    log = LogProgress(total, len(done))
                    evaluate(
                        episodes,
                        configs,
                        jobs,
                        lambda name, n, _t: log(n, name),
                        save,
                        finished,
                        ray=ray,
                        done=done,
                    )
            except Interrupted as stop:
                outcome.stopped_by, outcome.exit_code = stop.signame, stop.exit_code
        outcome.new = store.count
    return outcome


@dataclass
class StudyOutcome:
    results: list  # LocResult, in the order of the starts (finished ones only if stopped)
    new: int
    resumed: int
    total: int
    stopped_by: str | None = None
    exit_code: int = 0


STUDY = "localization"


def run_stored_study(starts: list, config: Config, run: StoredRun) -> StudyOutcome:
    """The Table 3 study as a run that survives (see ``run_stored_evaluation``)."""
    from dataclasses import asdict

    from pmnav_bt.experiments.localization_study import result_of_row, run_study, start_key
    from pmnav_bt.experiments.progress import LogProgress
    from pmnav_bt.interrupts import Interrupted, stop_signals

    out, jobs, ray, resume, echo = run.out, run.jobs, run.ray, run.resume, run.echo
    keys = [record_key(STUDY, start_key(s)) for s in starts]
    chash = config_hash(config)
    expected = [
        Expected(k, STUDY, stable_hash(asdict(s)), chash) for k, s in zip(keys, starts, strict=True)
    ]
    index = {k: i for i, k in enumerate(keys)}
    got: list = []
    with ResultStore(out / "results.jsonl", expected, resume) as store:
        done = {index[k]: row for k, row in store.done.items()}
        if resume:
            echo(f"resuming {out / 'results.jsonl'}: {len(done)} of {len(starts)} runs done")
        log = LogProgress(len(starts), len(done), what="localization runs")
        outcome = StudyOutcome([], 0, len(done), len(starts))
        with stop_signals():
            try:
                outcome.results = run_study(
                    starts,
                    config,
                    jobs=jobs,
                    progress=lambda n, _t: log(n),
                    ray=ray,
                    done=done,
                    on_row=lambda i, row: store.write(keys[i], row),
                    finished=got,
                )
            except Interrupted as stop:
                outcome.stopped_by, outcome.exit_code = stop.signame, stop.exit_code
                outcome.results = [result_of_row(r) for _, r in sorted(got, key=lambda p: p[0])]
        outcome.new = store.count
    return outcome
