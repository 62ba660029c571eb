"""Room numbering schemes of real buildings: how the number on a door plate is spelled.

Each generated building uses one scheme, as a real one does. Given the floor, the room's
sequence number ``n`` and the letter of its wing, a scheme spells the code:

- ``117``: floor digit and two-digit sequence (US and Asian practice): 101, 102 ...
- ``1G``: sequence number and wing letter (suites and wards: 1G, 2G ... 1H): per wing.
- ``2.04``: floor, point, two-digit sequence (UK universities and schools): 2.01, 2.02 ...
- ``L2-204``: level prefix, then floor and sequence (large hospitals and offices).
- ``B117``: wing (block) letter, floor and sequence (A101, B101 ...): per wing.

Sequence numbers run from the core outward, corridor by corridor; in a building numbered
``odd_even`` the left wall gets the odd numbers and the right wall the even ones (a street's
house numbers), else the rooms are numbered in the order one passes them. Either way the
codes along one corridor differ in one character (114, 115, 116), and the per-wing schemes
repeat a number in every wing (A101, B101): the near-identical codes real buildings have.

A building read from a file may number its rooms any way: ``parse_scheme`` reads the scheme
off its codes (prefix letters, digit groups and their separators, suffix letters) rather
than assuming one, and says which of ``SCHEMES`` it is, if any.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass

SCHEMES: dict[str, str] = {
    "117": "floor and two-digit sequence: 101, 102 ...",
    "1G": "sequence and wing letter: 1A, 2A ... 1B (numbered per wing)",
    "2.04": "floor, point, two-digit sequence: 2.01, 2.02 ...",
    "L2-204": "level prefix, floor and sequence: L2-201, L2-202 ...",
    "B117": "wing letter, floor and sequence: A101, B101 ... (numbered per wing)",
}
PER_WING = frozenset({"1G", "B117"})  # schemes whose sequence restarts in every wing


def room_code(scheme: str, floor: int, n: int, wing: str) -> str:
    """The code of room ``n`` (1-based) of ``wing`` (a letter) on ``floor`` in ``scheme``."""
    if n < 1:
        raise ValueError(f"room sequence numbers start at 1, not {n}")
    if scheme == "117":
        return f"{floor}{n:02d}"
    if scheme == "1G":
        return f"{n}{wing}"
    if scheme == "2.04":
        return f"{floor}.{n:02d}"
    if scheme == "L2-204":
        return f"L{floor}-{floor}{n:02d}"
    if scheme == "B117":
        return f"{wing}{floor}{n:02d}"
    raise ValueError(f"unknown numbering scheme {scheme!r}; choose {', '.join(SCHEMES)}")


def wing_letter(index: int) -> str:
    """The letter of the ``index``-th wing (0 -> A), skipping I and O (read as 1 and 0)."""
    letters = "ABCDEFGHJKLMNPQRSTUVWXYZ"
    if index < len(letters):
        return letters[index]
    return letters[index // len(letters) - 1] + letters[index % len(letters)]


# -- parsing a building's scheme ----------------------------------------------------------

# Characters OCR reads for a digit and digits it reads for a letter: where a code's shape
# wants a digit, a look-alike letter still fits it (and the other way round).
DIGIT_LOOKALIKES = frozenset("oilzsbgdq|")
LETTER_LOOKALIKES = frozenset("0124568")
# The shapes (``code_shape``) each scheme of ``SCHEMES`` writes, for any floor and sequence.
SCHEME_SHAPES = {
    "117": re.compile(r"^9{2,}$"),
    "1G": re.compile(r"^9+a$"),
    "2.04": re.compile(r"^9+\.9+$"),
    "L2-204": re.compile(r"^a9+-9+$"),
    "B117": re.compile(r"^a9{2,}$"),
}


def code_shape(code: str) -> str:
    """A code's shape: letters as ``a``, digits as ``9``, separators kept
    (``"L2-204"`` -> ``"a9-999"``, ``"2.04"`` -> ``"9.99"``, ``"1G"`` -> ``"9a"``)."""
    return "".join("9" if c.isdigit() else "a" if c.isalpha() else c for c in code.casefold())


@dataclass(frozen=True)
class NumberingScheme:
    """How one building spells its room codes, parsed from the codes it has.

    ``shapes``: every code's shape (``code_shape``); ``prefixes`` and ``suffixes``: the
    letters before the first digit and after the last (level and wing letters, suites);
    ``separators``: the characters between digit groups; ``digits``: how many digits a code
    carries (min, max). ``name`` is the scheme of ``SCHEMES`` the shapes are, or
    ``"mixed"`` where the building uses several or one of its own; ``"none"`` without codes.
    """

    shapes: frozenset[str]
    prefixes: frozenset[str]
    suffixes: frozenset[str]
    separators: frozenset[str]
    digits: tuple[int, int]
    name: str

    @property
    def lengths(self) -> tuple[int, int]:
        """The shortest and the longest code (characters)."""
        if not self.shapes:
            return (0, 0)
        return (min(map(len, self.shapes)), max(map(len, self.shapes)))

    def looks_like_code(self, token: str) -> bool:
        """Whether ``token`` (casefolded) could be one of this building's codes as OCR reads
        it: its shape is one of the scheme's within one edit, counting a look-alike letter
        as a digit and a look-alike digit as a letter."""
        t = token.casefold()
        if not self.shapes or not any(c.isdigit() or c in DIGIT_LOOKALIKES for c in t):
            return False
        return any(_fits(t, s) for s in self.shapes)

    def parses(self, token: str) -> bool:
        """Whether ``token`` (casefolded) is spelled as one of this building's codes,
        character for character (a look-alike letter still counting as a digit and the
        other way round): "79" or "2O9x" in a building of "209"s only looks like a code,
        one character dropped or added, and is not one as read."""
        t = token.casefold()
        return any(
            len(t) == len(s) and all(c in _classes(a) for a, c in zip(t, s, strict=True))
            for s in self.shapes
        )


def _classes(c: str) -> str:
    """The shape characters that ``c`` may stand for as read."""
    if c.isdigit():
        return "9a" if c in LETTER_LOOKALIKES else "9"
    if c.isalpha():
        return "a9" if c in DIGIT_LOOKALIKES else "a"
    return c + ("." if c == "," else "")


def _fits(token: str, shape: str) -> bool:
    """Edit distance of ``token`` to ``shape`` (character classes) is at most one."""
    n, m = len(token), len(shape)
    if abs(n - m) > 1:
        return False
    prev = list(range(m + 1))
    for i in range(1, n + 1):
        cur = [i] + [0] * m
        for j in range(1, m + 1):
            same = shape[j - 1] in _classes(token[i - 1])
            cur[j] = min(prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (not same))
        prev = cur
    return prev[m] <= 1


def parse_scheme(codes: Iterable[str]) -> NumberingScheme:
    """The numbering scheme that ``codes`` (a building's room codes) follow."""
    codes = [c.casefold() for c in codes if c]
    shapes = frozenset(code_shape(c) for c in codes)
    prefixes, suffixes, seps, n_digits = set(), set(), set(), []
    for c in codes:
        lead = len(c) - len(c.lstrip("abcdefghijklmnopqrstuvwxyz"))
        tail = len(c) - len(c.rstrip("abcdefghijklmnopqrstuvwxyz"))
        if lead:
            prefixes.add(c[:lead])
        if tail:
            suffixes.add(c[len(c) - tail :])
        seps.update(ch for ch in c if not ch.isalnum())
        n_digits.append(sum(ch.isdigit() for ch in c))
    named = [k for k, rx in SCHEME_SHAPES.items() if shapes and all(rx.match(s) for s in shapes)]
    name = "none" if not shapes else named[0] if named else "mixed"
    return NumberingScheme(
        shapes,
        frozenset(prefixes),
        frozenset(suffixes),
        frozenset(seps),
        (min(n_digits), max(n_digits)) if n_digits else (0, 0),
        name,
    )
