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
"""

from __future__ import annotations

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
