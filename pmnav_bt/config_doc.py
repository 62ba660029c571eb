"""docs/config.md, written from the config itself:

    python -m pmnav_bt.config_doc > docs/config.md

The page is the ``Config`` docstring, then one table per section (the section's docstring
above it): each key with its default, the values it may take (from the field's type and
bounds) and its ``Field(description=...)``; last, the back ends each seam's registry
holds. ``tests/core/test_config.py`` fails when the committed page differs from this output,
so a key cannot be added, renamed or re-described without the page following.
"""

from __future__ import annotations

import inspect
import sys
import typing
from typing import Any, Literal

from pydantic.fields import FieldInfo

from pmnav_bt.config import Config
from pmnav_bt.registry import REGISTRIES

COMMAND = "python -m pmnav_bt.config_doc > docs/config.md"


def config_doc() -> str:
    """The whole page, as Markdown."""
    out = [
        "# The run configuration",
        "",
        f"<!-- Generated from pmnav_bt/config.py by `{COMMAND}`; edit the config's "
        "docstrings and field descriptions, not this file. -->",
        "",
        inspect.cleandoc(Config.__doc__ or ""),
    ]
    for name, field in Config.model_fields.items():
        out += ["", f"## {name}", ""]
        section = field.annotation
        if section.__doc__:
            out += [inspect.cleandoc(section.__doc__), ""]
        out += ["| key | default | values | meaning |", "|---|---|---|---|"]
        for key, f in section.model_fields.items():
            meaning = (f.description or "").replace("|", "\\|")
            out.append(f"| `{key}` | {_default(f)} | {_values(f)} | {meaning} |")
    out += ["", "## Back ends", "", _BACKENDS_INTRO, ""]
    out += ["| seam | back end | what it is |", "|---|---|---|"]
    for seam, registry in REGISTRIES.items():
        for backend in registry.names():
            out.append(f"| `{seam}` | `{backend}` | {registry.spec(backend).summary} |")
    return "\n".join(out) + "\n"


_BACKENDS_INTRO = inspect.cleandoc(
    """Each seam's back ends are registered by name (`pmnav_bt/registry.py`) and built by
    one factory, `build_backends` (`pmnav_bt/backends.py`), from the `backend` keys above,
    for the simulator and the robot alike; `pmnav backends` lists them. A back end that
    reads the simulator's labels is refused on a robot with one line naming the others;
    `pmnav-ros` counts as a robot unless it subscribes to a segmentation topic (the
    simulated Create 3 publishes one). An unknown name is a config error that lists the
    registered ones. A new back end: `BackendSpec(name, "package.module:factory", summary)`
    registered on the seam's registry (a grounder: `GrounderSpec`, which also declares its
    reading model and whether it is an oracle); the factory gets the config, the
    priori-map, the seed and (for coarse direction) the run's grounder."""
)


def _default(f: FieldInfo) -> str:
    if f.default_factory is not None:
        return f"`{f.default_factory()!r}`"
    return "unset" if f.default is None else f"`{f.default!r}`"


def _values(f: FieldInfo) -> str:
    """What the key may be: its choices, its bounds or its type."""
    choices = _choices(f.annotation)
    if choices:
        return " \\| ".join(f"`{c}`" for c in choices)
    bounds = []
    for m in f.metadata:  # pydantic's bounds: annotated_types Ge(ge=0.0), Le(le=1.0) ...
        for attr, sign in (("ge", ">="), ("gt", ">"), ("le", "<="), ("lt", "<")):
            if getattr(m, attr, None) is not None:
                bounds.append(f"{sign} {getattr(m, attr)}")
    args = typing.get_args(f.annotation)
    optional = type(None) in args
    kind = _type_name(next(a for a in args if a is not type(None)) if optional else f.annotation)
    return kind + (" " + ", ".join(bounds) if bounds else "") + (", or unset" if optional else "")


def _choices(annotation: Any) -> tuple | None:
    if typing.get_origin(annotation) is Literal:
        return typing.get_args(annotation)
    return None


def _type_name(annotation: Any) -> str:
    if typing.get_origin(annotation) is list:
        return f"list of {_type_name(typing.get_args(annotation)[0])}"
    return {bool: "true/false", int: "integer", float: "number", str: "text"}.get(
        annotation, str(annotation)
    )


if __name__ == "__main__":
    sys.stdout.write(config_doc())
