"""``pmnav pixelnav``: make the training data in the simulator, train the PixelNav policy,
export it, evaluate the skill against the geometric refiner."""

from __future__ import annotations

import json
from pathlib import Path

import typer

from pmnav_bt import cli_values
from pmnav_bt.loading import check_output_dir, check_output_file

app = typer.Typer(
    add_completion=False,
    pretty_exceptions_enable=False,
    no_args_is_help=True,
    help="PixelNav: the pixel-goal policy that drives the approach (refiner.backend=pixelnav).",
)


@app.callback()
def _group() -> None:
    """PixelNav: the pixel-goal policy that drives the approach (refiner.backend=pixelnav)."""


@app.command()
def gen(
    out: Path = typer.Option(Path("out/pixelnav/data"), "--out", help="Folder for the shards."),
    shards: int = typer.Option(80, "--shards", min=1, help="Shards (one building each)."),
    episodes: int = typer.Option(50, "--episodes", min=1, help="Episodes per shard."),
    seed: int = typer.Option(0, "--seed"),
    noise: float = typer.Option(0.1, "--noise", min=0.0, max=1.0, help="Random-move chance."),
) -> None:
    """Expert rollouts to goal pixels on generated buildings, as resumable .npz shards."""
    from pmnav_bt.experiments.pixelnav_data import DataConfig, generate

    cli_values.seed(seed)
    check_output_dir(out)
    cfg = DataConfig(seed=seed, shards=shards, episodes_per_shard=episodes, noise=noise)
    paths = generate(cfg, out)
    steps = sum(int(len(_np_load(p)["actions"])) for p in paths)
    typer.echo(f"{len(paths)} shards, {shards * episodes} episodes, {steps} frames in {out}")


def _np_load(path: Path):
    import numpy as np

    return np.load(path)


@app.command()
def train(
    data: list[Path] = typer.Option(
        [Path("out/pixelnav/data")],
        "--data",
        help="gen's folder; repeat for several (validation: the last folder's last shards).",
    ),
    out: Path = typer.Option(Path("out/pixelnav/train"), "--out", help="Checkpoints, curves."),
    model: str = typer.Option("small", "--model", help="tiny, small (CPU) or large (GPU)."),
    steps: int = typer.Option(4000, "--steps", min=1),
    batch: int = typer.Option(32, "--batch", min=1),
    lr: float = typer.Option(1e-3, "--lr", min=0.0),
    seed: int = typer.Option(0, "--seed"),
    threads: int = typer.Option(1, "--threads", min=1, help="CPU threads for torch."),
    eval_every: int = typer.Option(250, "--eval-every", min=1),
    history: int = typer.Option(0, "--history", min=0, help="Frames the model sees (0: preset's)."),
    stop_weight: float = typer.Option(2.0, "--stop-weight", min=0.0, help="CE weight of STOP."),
    warmup: int = typer.Option(200, "--warmup", min=0, help="Steps of linear lr warm-up."),
    init: Path | None = typer.Option(
        None, "--init", help="Fine-tune from these weights (.safetensors) instead of scratch."
    ),
) -> None:
    """Imitation training (resumes from --out's checkpoint); curves.png beside it."""
    from pmnav_bt.pixelnav.train import TrainConfig, preset
    from pmnav_bt.pixelnav.train import train as run

    cli_values.seed(seed)
    check_output_dir(out)
    arch = preset(model)
    if history:
        arch = arch.model_copy(update={"history": history})
    cfg = TrainConfig(
        model=arch,
        steps=steps,
        batch=batch,
        lr=lr,
        seed=seed,
        threads=threads,
        eval_every=eval_every,
        stop_weight=stop_weight,
        warmup=warmup,
        init=str(init) if init else "",
    )
    state = run(data, out, cfg)
    last = state["history"][-1] if state["history"] else {}
    typer.echo(
        f"{state['step']} steps in {state['seconds'] / 60:.1f} min; val loss "
        f"{last.get('val_loss', float('nan')):.3f}, val action accuracy "
        f"{last.get('val_acc', float('nan')):.3f}; {out / 'curves.png'}"
    )


@app.command()
def export(
    run_dir: Path = typer.Option(Path("out/pixelnav/train"), "--run", help="train's folder."),
    dest: Path = typer.Option(
        Path("pmnav_bt/pixelnav/weights/pixelnav_small.safetensors"),
        "--dest",
        help="The .safetensors to write (its .json beside it).",
    ),
    stop_threshold: float = typer.Option(
        0.5, "--stop-threshold", min=0.0, max=1.0, help="STOP once its probability is this."
    ),
    stop_steps: float | None = typer.Option(
        None, "--stop-steps", min=0.0, help="Also STOP when at most this many steps are left."
    ),
) -> None:
    """Write a trained model as safetensors + JSON config (what refiner.weights loads)."""
    from pmnav_bt.pixelnav.train import export as run

    check_output_file(dest, "--dest", (".safetensors",))
    w, j = run(run_dir, dest, stop_threshold, stop_steps)
    typer.echo(f"{w} ({w.stat().st_size / 1e6:.1f} MB), {j}")


@app.command("eval")
def eval_(
    weights: str = typer.Option("", "--weights", help="A .safetensors; default: shipped."),
    buildings: int = typer.Option(8, "--buildings", min=1, help="Held-out generated buildings."),
    n: int = typer.Option(25, "-n", min=1, help="Goals per building."),
    seed: int = typer.Option(0, "--seed"),
    out: Path = typer.Option(Path("out/pixelnav/eval"), "--out", help="Folder for results."),
    validation: bool = typer.Option(
        False,
        "--validation",
        help="On the validation buildings of gen's seed-0 shards 73-79 (to choose "
        "--stop-threshold), not the held-out ones.",
    ),
    stop_threshold: float | None = typer.Option(
        None, "--stop-threshold", min=0.0, max=1.0, help="Override the weights' threshold."
    ),
    stop_steps: float | None = typer.Option(
        None, "--stop-steps", min=0.0, help="Override the weights' steps-left STOP rule."
    ),
) -> None:
    """The skill alone: PixelNav vs the geometric refiner on the same held-out goals
    (success: stopped within 1 m of the goal point within 64 steps)."""
    import torch

    from pmnav_bt.experiments.pixelnav_eval import (
        evaluate,
        failures,
        format_failures,
        format_table,
        table,
        trials_json,
    )
    from pmnav_bt.pixelnav.policy import PixelNavPolicy

    cli_values.count(n, "-n")
    cli_values.seed(seed)
    check_output_dir(out)
    torch.set_num_threads(1)  # small steps: one thread is as fast and shares the machine
    policy = PixelNavPolicy.load(weights or None)
    if stop_threshold is not None:
        policy.stop_threshold = stop_threshold
    if stop_steps is not None:
        policy.stop_steps = stop_steps
    trials = evaluate(policy, buildings, n, seed=seed, validation=validation)
    rows, why = table(trials), failures(trials)
    text = format_table(rows) + "\n\n" + format_failures(why)
    (out / "skill.json").write_text(
        json.dumps({"rows": rows, "failures": why, "trials": trials_json(trials)}, indent=1),
        encoding="utf-8",
    )
    (out / "skill.txt").write_text(text + "\n", encoding="utf-8")
    typer.echo(text)


@app.command()
def calibrate(
    weights: str = typer.Option("", "--weights", help="A .safetensors; default: shipped."),
    buildings: int = typer.Option(6, "--buildings", min=1, help="Validation buildings."),
    n: int = typer.Option(25, "-n", min=1, help="Goals per building."),
    seed: int = typer.Option(0, "--seed"),
    thresholds: str = typer.Option(
        "0.02,0.05,0.1,0.15,0.2,0.3,0.4,0.5", "--thresholds", help="STOP probabilities to try."
    ),
    steps: str = typer.Option(
        "off,0.5,1,1.5,2,3", "--steps", help="Steps-left STOP rules to try (off: none)."
    ),
    out: Path = typer.Option(Path("out/pixelnav/calibrate"), "--out", help="Folder for results."),
) -> None:
    """Choose the STOP rule on validation buildings (never the held-out ones): one
    STOP-free closed-loop trace per goal answers every rule exactly; SR per rule."""
    import torch

    from pmnav_bt.experiments.pixelnav_eval import evaluate, sweep
    from pmnav_bt.pixelnav.policy import PixelNavPolicy

    cli_values.count(n, "-n")
    cli_values.seed(seed)
    check_output_dir(out)
    ths = [cli_values.parse_number(x, "--thresholds") for x in thresholds.split(",")]
    sts = [
        None if x.strip() == "off" else cli_values.parse_number(x, "--steps")
        for x in steps.split(",")
    ]
    torch.set_num_threads(1)
    policy = PixelNavPolicy.load(weights or None)
    traces: list = []
    evaluate(policy, buildings, n, seed=seed, validation=True, traces=traces)
    rows = sweep(traces, ths, sts)
    head = "threshold " + " ".join(f"{'off' if s is None else f'<={s:g}':>6}" for s in sts)
    lines = [f"SR by STOP rule, {len(traces)} validation goals (columns: steps left)", head]
    for th in ths:
        cells = [r for r in rows if r["stop_threshold"] == th]
        lines.append(f"{th:>9g} " + " ".join(f"{r['sr']:>6.1%}" for r in cells))
    best = max(rows, key=lambda r: r["sr"])
    lines.append(
        f"best: --stop-threshold {best['stop_threshold']:g}"
        + ("" if best["stop_steps"] is None else f" --stop-steps {best['stop_steps']:g}")
        + f" (SR {best['sr']:.1%})"
    )
    (out / "calibrate.json").write_text(
        json.dumps({"rows": rows, "traces": traces}, indent=1), encoding="utf-8"
    )
    typer.echo("\n".join(lines))
