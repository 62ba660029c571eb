"""The ``pmnav`` program: the core commands (``pmnav_bt.cli``) with the simulator's
(``pmnav sim``), the tree's (``pmnav tree``), planning's (``pmnav plan``: a route, and
the Table 2 evaluation over the simulator's episodes) and PixelNav's (``pmnav pixelnav``:
data, training, the skill's evaluation) mounted on them.

This is where the command line joins simulator, tree and metrics, so it lives in the
experiments layer; the core CLI knows neither. Each sub-app imports only typer at module
level: pybullet and py_trees load inside the commands that need them.
"""

from __future__ import annotations

import sys

from pmnav_bt.cli import app
from pmnav_bt.cli import main as _run
from pmnav_bt.experiments.pixelnav_cli import app as pixelnav_app
from pmnav_bt.experiments.plan_cli import app as plan_app
from pmnav_bt.experiments.report import report
from pmnav_bt.experiments.sim_cli import app as sim_app
from pmnav_bt.trees.cli import app as tree_app

app.add_typer(plan_app, name="plan")
app.add_typer(sim_app, name="sim")
app.add_typer(tree_app, name="tree")
app.add_typer(pixelnav_app, name="pixelnav")
app.command("report")(report)


def optional_value(args: list[str], option: str, default: str) -> list[str]:
    """``--ray`` may stand alone: give it ``default`` when no value follows it."""
    out = list(args)
    for i, a in enumerate(out):
        if a == "--":
            break
        if a == option and (i + 1 == len(out) or out[i + 1].startswith("-")):
            out.insert(i + 1, default)
    return out


def main(argv: list[str] | None = None) -> None:
    """Entry point of ``pmnav``: user errors become one line on stderr and exit status 2."""
    args = list(sys.argv[1:] if argv is None else argv)
    _run(optional_value(args, "--ray", "local"))


if __name__ == "__main__":  # pragma: no cover
    main()
