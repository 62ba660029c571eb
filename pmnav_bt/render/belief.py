"""The corridor belief drawn over its building, one picture per step, as PythonRobotics
draws its filters: to see what the belief holds and why it moves.

Each picture shows the priori-map's corridors (grey, walls dark), every sign the map has
(small squares; those read so far named and starred), where each likely hypothesis puts
the robot now (an arrow, coloured by its weight on a log scale), the best cluster (a
circle, with the share of the belief it holds), the true pose (red) and the fixed pose
once there is one (green). The title says what the step added (the signs read, doors
seen, depth readings along a drive) and how sure the belief is.

matplotlib, headless (Agg), as ``pmnav report`` draws its charts.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pmnav_bt.geometry import se2_compose
from pmnav_bt.pose.belief import CorridorBelief
from pmnav_bt.pose.hypotheses import apply_many
from pmnav_bt.pose.visibility import entity_xy
from pmnav_bt.render import headless_pyplot
from pmnav_bt.seams import Pose2D

SHOWN_WEIGHT = 1e-3  # hypotheses this likely (of the best) are drawn
TRUE_COLOUR = "#d62728"
FIX_COLOUR = "#2ca02c"
CLUSTER_COLOUR = "#ff7f0e"
SIGN_COLOUR = "#1f77b4"
WEIGHT_CMAP = "plasma_r"  # light: unlikely, dark: likely


@dataclass(frozen=True)
class BeliefStep:
    """One step to draw: ``title`` (what the step added), the ``belief`` after it (a
    fork, not changed afterwards), the robot's odometry pose ``odom`` then, the ``truth``
    (map; None: not known) and the fix taken (``map_T_odom``; None: none yet)."""

    title: str
    belief: CorridorBelief
    odom: Pose2D
    truth: Pose2D | None = None
    fix: tuple[float, float, float] | None = None


def hypotheses_now(belief: CorridorBelief, odom: Pose2D) -> tuple[np.ndarray, np.ndarray]:
    """Where each hypothesis puts the robot at odometry pose ``odom``: (N, 2) map
    positions and (N,) map headings."""
    tfs = belief.map_T_odoms()
    p = belief.straighten((odom.x, odom.y))
    here = apply_many(tfs, (p[0], p[1]))
    heading = np.angle(np.exp(1j * (tfs[:, 2] + odom.yaw - belief.drift)))
    return here, heading


def draw_belief(ax, step: BeliefStep, legend: bool = True, small: bool = False) -> None:
    """Draw ``step`` on the matplotlib axes ``ax``."""
    from matplotlib.colors import LogNorm

    b = step.belief
    corridors = b.vis.corridors
    for poly in getattr(corridors, "geoms", [corridors]):
        x, y = poly.exterior.xy
        ax.fill(x, y, color="#e6e6e6", zorder=0)
        ax.plot(x, y, color="#555555", lw=0.8, zorder=1)
        for hole in poly.interiors:
            hx, hy = hole.xy
            ax.fill(hx, hy, color="white", zorder=0)
            ax.plot(hx, hy, color="#555555", lw=0.8, zorder=1)
    signs = b.vis.sign_xy
    ax.scatter(signs[:, 0], signs[:, 1], marker="s", s=6 if small else 10, color="#999999",
               zorder=2, label="sign on the map")  # fmt: skip
    read = sorted({e for e, _ in b.sightings()}, key=str)
    if read:
        xy = np.array([entity_xy(b.pm, e) for e in read])
        ax.scatter(xy[:, 0], xy[:, 1], marker="*", s=60 if small else 140, color=SIGN_COLOUR,
                   edgecolor="white", lw=0.5, zorder=6, label="sign read")  # fmt: skip
        if not small:
            for e, p in zip(read, xy, strict=True):
                ax.annotate(str(e.id), p, xytext=(4, 4), textcoords="offset points",
                            fontsize=7, color=SIGN_COLOUR, zorder=7)  # fmt: skip
    mass = 0.0
    if b.ref is not None:
        w = b.weights()
        here, heading = hypotheses_now(b, step.odom)
        shown = np.nonzero(w >= SHOWN_WEIGHT * w.max())[0]
        shown = shown[np.argsort(w[shown])]  # the likeliest on top
        length = 2.4 if small else 1.6
        q = ax.quiver(
            here[shown, 0], here[shown, 1], np.cos(heading[shown]), np.sin(heading[shown]),
            w[shown] / w.max(), cmap=WEIGHT_CMAP, norm=LogNorm(SHOWN_WEIGHT, 1.0),
            angles="xy", scale_units="xy", scale=1.0 / length, width=0.006 if small else 0.004,
            zorder=4,
        )  # fmt: skip
        ax.plot([], [], ls="", marker=r"$\rightarrow$", ms=12, color=q.cmap(0.9),
                label="hypothesis (where it puts the robot)")  # fmt: skip
        if legend:
            bar = ax.figure.colorbar(q, ax=ax, fraction=0.035, pad=0.01)
            bar.set_label("hypothesis weight (of the likeliest)", fontsize=8)
            bar.ax.tick_params(labelsize=7)
        idx, mass = b.best_cluster()
        centre = (w[idx, None] * here[idx]).sum(0) / w[idx].sum()
        spread = max(1.0, float(np.sqrt((w[idx] * ((here[idx] - centre) ** 2).sum(1)).sum()
                                        / w[idx].sum())) * 2.0)  # fmt: skip
        ax.add_patch(_circle(centre, spread, CLUSTER_COLOUR))
        ax.plot([], [], color=CLUSTER_COLOUR, lw=2, label="best cluster")
        if not small:
            ax.annotate(f"{mass:.0%}", centre, xytext=(spread * 3 + 6, -4),
                        textcoords="offset points", fontsize=9, weight="bold",
                        color=CLUSTER_COLOUR, zorder=8)  # fmt: skip
    if step.fix is not None:
        x, y, yaw = se2_compose(step.fix, (step.odom.x, step.odom.y, step.odom.yaw))
        _arrow(ax, x, y, yaw, FIX_COLOUR, "fixed pose", small, -1.0)
    if step.truth is not None:
        t = step.truth
        _arrow(ax, t.x, t.y, t.yaw, TRUE_COLOUR, "true pose", small, 1.0)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])
    title = step.title if b.ref is None else f"{step.title}\nbest cluster {mass:.0%}"
    ax.set_title(title, fontsize=7 if small else 10, loc="left")
    if legend:
        ax.legend(loc="upper left", bbox_to_anchor=(1.12, 1.0), fontsize=8, frameon=False)


def _circle(centre, radius: float, colour: str):
    from matplotlib.patches import Circle

    return Circle(tuple(centre), radius, fill=False, ec=colour, lw=2, zorder=5)


def _arrow(
    ax, x: float, y: float, yaw: float, colour: str, label: str, small: bool, side: float
) -> None:
    """A pose as an arrow from a ring, drawn a little to ``side`` (+1 left, -1 right of
    its heading) so that the true and the fixed pose do not hide each other; the arrow
    under the hypotheses (they are what the picture is about), the ring over them."""
    size = 4.0 if small else 3.0
    off = 0.6 * side
    x, y = x - off * math.sin(yaw), y + off * math.cos(yaw)
    ax.annotate("", (x + size * math.cos(yaw), y + size * math.sin(yaw)), (x, y),
                arrowprops={"arrowstyle": "-|>,head_width=0.4,head_length=0.8",
                            "color": colour, "lw": 2.0, "alpha": 0.85}, zorder=3)  # fmt: skip
    ax.scatter([x], [y], facecolor="none", edgecolor=colour, s=70, lw=2.0, zorder=9,
               label=label)  # fmt: skip


def _figsize(b: CorridorBelief, width: float) -> tuple[float, float]:
    x0, y0, x1, y1 = b.vis.corridors.bounds
    return width, max(2.5, width * 0.75 * (y1 - y0) / max(1e-6, x1 - x0))


def render_step(step: BeliefStep, path: str | Path, width: float = 9.0) -> Path:
    """One step as a PNG at ``path``."""
    plt = headless_pyplot()
    fig, ax = plt.subplots(figsize=_figsize(step.belief, width))
    draw_belief(ax, step)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return Path(path)


def render_sheet(steps: list[BeliefStep], path: str | Path, cols: int = 4) -> Path:
    """Every step small on one contact sheet (row by row, in order) as a PNG at ``path``."""
    plt = headless_pyplot()
    if not steps:
        raise ValueError("no steps to draw")
    cols = min(cols, len(steps))
    rows = math.ceil(len(steps) / cols)
    w, h = _figsize(steps[0].belief, 4.0)
    fig, axes = plt.subplots(rows, cols, figsize=(w * cols, h * rows + 0.6), squeeze=False)
    for ax in axes.flat[len(steps):]:
        ax.axis("off")
    for ax, step in zip(axes.flat, steps, strict=False):
        draw_belief(ax, step, legend=False, small=True)
    handles, labels = axes.flat[0].get_legend_handles_labels()
    for ax in axes.flat[1 : len(steps)]:  # a step may show what the first did not
        for hd, lb in zip(*ax.get_legend_handles_labels(), strict=True):
            if lb not in labels:
                handles.append(hd)
                labels.append(lb)
    fig.legend(handles, labels, loc="lower center", ncol=len(labels), fontsize=9,
               frameon=False)  # fmt: skip
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return Path(path)
