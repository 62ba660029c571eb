"""From a VLM answer to raw plan steps: tolerant of JSON, code fences and the paper's text.

Accepted, in this order of preference:

1. JSON, in a markdown code fence or bare: ``{"plan": [{"landmark": "room8", "action":
   "go straight"}, ...]}``, or just the list, or ``[{"room8": "go straight"}, ...]``, or
   ``[["room8", "go straight"], ...]``;
2. the paper's notation anywhere in the text: ``{room8: go straight} -> {turn2: turn left}``
   (chains and one pair per line alike; a step repeated at the join is kept once).

JSON that starts but does not parse (cut off at the token limit, a stray comma) is a
``ParseFailure`` of kind ``malformed_json``; text with neither is ``no_plan``. Names and
actions stay as written here; the validator resolves them against the map.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from typing import Any

_FENCE = re.compile(r"```[ \t]*([A-Za-z]*)[ \t]*\n?(.*?)(?:```|\Z)", re.DOTALL)
_PAPER = re.compile(
    r"\{\s*\"?([A-Za-z][\w\- ]{0,40}?)\"?\s*:\s*\"?([A-Za-z][A-Za-z \-]{0,30}?)\"?\s*\}"
)
_LOOKS_JSON = re.compile(r"[\[{]\s*[\"\[{]")
_STEP_KEYS = ("landmark", "name", "id", "waypoint", "node", "target", "room")
_ACTION_KEYS = ("action", "act", "move", "instruction")


@dataclass(frozen=True)
class RawStep:
    """A step as the VLM wrote it."""

    name: str
    action: str


@dataclass(frozen=True)
class ParseFailure(Exception):
    """The answer holds no readable plan. ``kind``: no_plan | malformed_json."""

    kind: str
    message: str

    def __str__(self) -> str:
        return self.message


def parse_plan(text: str) -> list[RawStep]:
    """The steps of a plan answer; raises ParseFailure when there are none."""
    json_error = None
    for candidate in _json_candidates(text):
        try:
            data = json.loads(candidate)
        except ValueError as err:
            json_error = json_error or err
            continue
        steps = _steps_from_json(data)
        if steps:
            return _dedupe(steps)
    if json_error is not None:  # JSON was meant: do not salvage a part of it
        raise ParseFailure(
            "malformed_json",
            f"the JSON plan is cut off or malformed ({json_error.msg} at character "
            f"{json_error.pos}); send the whole plan as valid JSON",
        )
    paper = [RawStep(m.group(1).strip(), m.group(2).strip()) for m in _PAPER.finditer(text)]
    paper = [s for s in paper if s.name.lower() not in _STEP_KEYS + _ACTION_KEYS + ("plan",)]
    if paper:
        return _dedupe(paper)
    raise ParseFailure(
        "no_plan",
        "the answer holds no plan: give it as JSON "
        '{"plan": [{"landmark": ..., "action": ...}, ...]} in a ```json code block',
    )


def _json_candidates(text: str) -> list[str]:
    """Fenced blocks (last first: a model may correct itself), then the bare outermost
    JSON value of the text."""
    out = [m.group(2).strip() for m in _FENCE.finditer(text)]
    out = [c for c in reversed(out) if _LOOKS_JSON.match(c)]
    bare = _outermost(text)
    if bare and bare not in out:
        out.append(bare)
    return out


def _outermost(text: str) -> str | None:
    """From the first '{' or '[' that opens JSON-looking content to the end of its match
    (or to the end of the text, when it never closes)."""
    m = _LOOKS_JSON.search(text)
    if m is None:
        return None
    start, depth, in_str, esc = m.start(), 0, False, False
    for i in range(start, len(text)):
        c = text[i]
        if in_str:
            esc = c == "\\" and not esc
            if c == '"' and not esc:
                in_str = False
            continue
        if c == '"':
            in_str = True
        elif c in "[{":
            depth += 1
        elif c in "]}":
            depth -= 1
            if depth == 0:
                return text[start : i + 1]
    return text[start:]


def _steps_from_json(data: Any) -> list[RawStep]:
    if isinstance(data, dict):
        for key in ("plan", "steps", "route", "path", "navigation_plan"):
            if key in data:
                return _steps_from_json(data[key])
        # An ordered mapping {"room8": "go straight", ...}.
        if data and all(isinstance(v, str) for v in data.values()):
            return [RawStep(str(k), v) for k, v in data.items()]
        return []
    if not isinstance(data, list):
        return []
    steps = []
    for item in data:
        if isinstance(item, dict):
            name = next((item[k] for k in _STEP_KEYS if k in item), None)
            action = next((item[k] for k in _ACTION_KEYS if k in item), None)
            if name is None and len(item) == 1:
                name, action = next(iter(item.items()))
            if name is None or action is None:
                return []
            steps.append(RawStep(str(name), str(action)))
        elif isinstance(item, list | tuple) and len(item) == 2:
            steps.append(RawStep(str(item[0]), str(item[1])))
        elif isinstance(item, str) and (m := _PAPER.search(item)):
            steps.append(RawStep(m.group(1).strip(), m.group(2).strip()))
        else:
            return []
    return steps


def _dedupe(steps: list[RawStep]) -> list[RawStep]:
    """Drop a step that repeats the one before it (the join of two written pairs)."""
    out: list[RawStep] = []
    for s in steps:
        if out and _key(out[-1].name) == _key(s.name) and _key(out[-1].action) == _key(s.action):
            continue
        out.append(s)
    return out


def _key(s: str) -> str:
    return re.sub(r"[^0-9a-z]", "", s.casefold())
