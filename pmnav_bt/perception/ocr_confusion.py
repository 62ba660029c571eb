"""How likely the OCR reads a room code as it did: a character confusion model, from data.

The recogniser names one character per step with a confidence, and on small or blurred
text it confuses characters in ways one can count: B and 8, O and 0, I, 1 and l, S and 5,
G and 6, a dropped point, two digits swapped. ``benchmarks/ocr_confusions.py`` draws room
codes of every numbering scheme on the simulator's plate styles, reads them with the
project's own reader and counts what became of every character; this module turns those
counts into the likelihood of a reading given the code a plate carries. Each character
read is a read character ``r`` and the recogniser's confidence ``c`` in it:

    P(read | code) = the best alignment's product over its steps of
      a drawn t read as r (r = t or not):   P(r | t) * H(c | right or wrong)
      a character read that was not drawn:  p_ins * q_ins(r) * H(c | wrong)
      two neighbours read swapped:          p_swap * H(c | wrong)
      a drawn t not read:                   p_del(t)

``P(r | t)`` is the confusion table's row of ``t`` (its correct reads included); ``H`` the
histogram of the confidences of the characters ``r`` read right, and of those read wrong
(``CONFIDENCE_BINS``): the recogniser is sure of most wrong characters too, and the two
histograms say how much surer it is of right ones. They are per character read (a "1" it
is sure of was an I or an l more often than a sure "7" was anything else), mixed with the
histograms of all characters where a character has few reads (``CALIBRATION_PRIOR``).
Counts are smoothed: one pseudo-count spread over a row, ``RIGHT_COUNT`` right reads for a
character the data never drew, and ``LOOKALIKE_COUNT`` on each pair of ``LOOKALIKES``
(shapes any reader may take for each other, seen in the data or not). Codes and readings
are compared casefolded, spaces removed.
"""

from __future__ import annotations

import functools
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from pmnav_bt.errors import ConfigError

DATA_FILE = Path(__file__).parent.parent / "data" / "ocr_confusions.json"
# Lower edges of the recogniser-confidence bins of the calibration.
CONFIDENCE_BINS = (0.0, 0.6, 0.8, 0.9, 0.95, 0.98, 0.99, 0.995, 0.999)
ALPHABET = "0123456789abcdefghijklmnopqrstuvwxyz.-,:/"
UNKNOWN_SCORE = 0.9  # a character's confidence where the recogniser gave none
# Groups of characters of alike shape (casefolded): a misread within a group is expected.
LOOKALIKES = ("b8", "o0dq", "i1l", "s5", "z2", "g6c", ".,")
LOOKALIKE_COUNT = 2.0
RIGHT_COUNT = 8.0  # right reads assumed of a character the data never drew
CALIBRATION_PRIOR = 20.0  # reads of the overall calibration a character's own is mixed with

Op = tuple[str, str, str, int]  # kind (match, sub, ins, del, swap), drawn, read, read index


def align(drawn: str, read: str) -> list[Op]:
    """An alignment of ``read`` to ``drawn`` with the fewest edits (substitution, insertion,
    deletion, swap of two neighbours: each costs one); ops in reading order."""
    n, m = len(drawn), len(read)
    d = [[0] * (m + 1) for _ in range(n + 1)]
    for i in range(n + 1):
        d[i][0] = i
    for j in range(m + 1):
        d[0][j] = j
    for i in range(1, n + 1):
        for j in range(1, m + 1):
            d[i][j] = min(
                d[i - 1][j] + 1,
                d[i][j - 1] + 1,
                d[i - 1][j - 1] + (drawn[i - 1] != read[j - 1]),
            )
            if i > 1 and j > 1 and drawn[i - 1] == read[j - 2] and drawn[i - 2] == read[j - 1]:
                d[i][j] = min(d[i][j], d[i - 2][j - 2] + 1)
    ops: list[Op] = []
    i, j = n, m
    while i or j:
        if i and j and d[i][j] == d[i - 1][j - 1] + (drawn[i - 1] != read[j - 1]):
            kind = "match" if drawn[i - 1] == read[j - 1] else "sub"
            ops.append((kind, drawn[i - 1], read[j - 1], j - 1))
            i, j = i - 1, j - 1
        elif (
            i > 1
            and j > 1
            and drawn[i - 1] == read[j - 2]
            and drawn[i - 2] == read[j - 1]
            and drawn[i - 1] != drawn[i - 2]
            and d[i][j] == d[i - 2][j - 2] + 1
        ):
            ops.append(("swap", drawn[i - 2 : i], read[j - 2 : j], j - 2))
            i, j = i - 2, j - 2
        elif i and d[i][j] == d[i - 1][j] + 1:
            ops.append(("del", drawn[i - 1], "", j))
            i -= 1
        else:
            ops.append(("ins", "", read[j - 1], j - 1))
            j -= 1
    return ops[::-1]


@dataclass(frozen=True)
class ConfusionModel:
    """Likelihood of a reading given a code (see the module docstring); probabilities as
    logarithms."""

    read_as: dict[str, dict[str, float]]  # log P(r | t), r over ALPHABET
    conf_right: dict[str, tuple[float, ...]]  # log H(c | right, r) per bin of CONFIDENCE_BINS
    conf_wrong: dict[str, tuple[float, ...]]  # log H(c | wrong, r)
    ins: dict[str, float]  # log p_ins + log q_ins(r)
    swap: float  # log p_swap
    dele: dict[str, float]  # log p_del(t)
    chars: int  # characters in the data (n)
    # The share of characters read wrong in each bin of CONFIDENCE_BINS, all characters
    # pooled: how often a character read at that confidence is not what the plate shows.
    misread: tuple[float, ...] = ()

    @classmethod
    def from_counts(cls, t: dict) -> ConfusionModel:
        k = len(ALPHABET)
        alike = {(a, b) for g in LOOKALIKES for a in g for b in g if a != b}
        subs, right = t["substitutions"], t["correct"]
        read_as = {}
        for c in ALPHABET:
            row = {
                r: subs.get(c, {}).get(r, 0) + 1 / k + LOOKALIKE_COUNT * ((c, r) in alike)
                for r in ALPHABET
            }
            row[c] = right.get(c, 0) + (RIGHT_COUNT if not right.get(c) else 0)
            total = sum(row.values())
            read_as[c] = {r: math.log(n / total) for r, n in row.items()}
        calib = t["calibration"]
        ok_all = _histogram([r - w for r, w in zip(calib["read"], calib["wrong"], strict=True)])
        bad_all = _histogram(calib["wrong"])
        conf_right, conf_wrong = {}, {}
        for r in ALPHABET:
            none = [0] * len(ok_all)
            mine = calib["by_read"].get(r, {"read": none, "wrong": none})
            ok = [a - b for a, b in zip(mine["read"], mine["wrong"], strict=True)]
            conf_right[r] = _histogram(ok, ok_all)
            conf_wrong[r] = _histogram(mine["wrong"], bad_all)
        chars = int(t["chars"])
        ins_total = sum(t["insertions"].values())
        p_ins = (ins_total + 1) / (chars + 1)
        ins = {
            r: math.log(p_ins * (t["insertions"].get(r, 0) + 1 / k) / (ins_total + 1))
            for r in ALPHABET
        }
        swap = math.log((t["transpositions"] + 0.5) / (chars + 1))
        dele = {}
        for c in ALPHABET:
            seen = right.get(c, 0) + sum(subs.get(c, {}).values())
            d = t["deletions"].get(c, 0)
            dele[c] = math.log((d + 0.5) / (seen + d + 1))
        misread = tuple(
            (w + 0.5) / (n + 1) for n, w in zip(calib["read"], calib["wrong"], strict=True)
        )
        return cls(read_as, conf_right, conf_wrong, ins, swap, dele, chars, misread)

    def _bin(self, confidence: float) -> int:
        return max(0, sum(confidence >= b for b in CONFIDENCE_BINS) - 1)

    def p_misread(self, confidence: float) -> float:
        """How often a character read with ``confidence`` was read wrong (the calibration's
        share in its bin; 0.5 without a calibration)."""
        return self.misread[self._bin(confidence)] if self.misread else 0.5

    def log_read_right(self, read: str, scores: Sequence[float]) -> float:
        """log P(``read`` | the plate shows exactly ``read``)."""
        return sum(self._step(r, r, s) for r, s in zip(read, _scores(read, scores), strict=True))

    def _step(self, drawn: str, read: str, confidence: float) -> float:
        row = self.read_as.get(drawn)
        p = row.get(read, -20.0) if row is not None else -20.0
        hist = self.conf_right if drawn == read else self.conf_wrong
        return p + hist.get(read, self.conf_wrong["."])[self._bin(confidence)]

    def _wrong(self, read: str, confidence: float) -> float:
        return self.conf_wrong.get(read, self.conf_wrong["."])[self._bin(confidence)]

    def log_likelihood(self, read: str, scores: Sequence[float], code: str) -> float:
        """log P(``read`` with these character confidences | the plate shows ``code``): the
        best alignment (Viterbi), steps weighed as in the module docstring. ``read`` and
        ``code`` are casefolded with spaces removed; ``scores`` are ``read``'s."""
        sc = _scores(read, scores)
        n, m = len(code), len(read)
        neg = -math.inf
        f = [[neg] * (m + 1) for _ in range(n + 1)]
        f[0][0] = 0.0
        for i in range(n + 1):
            for j in range(m + 1):
                best = f[i][j]
                if i and j:
                    step = self._step(code[i - 1], read[j - 1], sc[j - 1])
                    best = max(best, f[i - 1][j - 1] + step)
                if j:
                    wrong = self._wrong(read[j - 1], sc[j - 1])
                    best = max(best, f[i][j - 1] + self.ins.get(read[j - 1], -20.0) + wrong)
                if i:
                    best = max(best, f[i - 1][j] + self.dele.get(code[i - 1], -3.0))
                if _swapped(code, read, i, j):
                    wrong = self._wrong(read[j - 1], min(sc[j - 1], sc[j - 2]))
                    best = max(best, f[i - 2][j - 2] + self.swap + wrong)
                f[i][j] = best
        return f[n][m]


def _histogram(counts: Sequence[float], prior: Sequence[float] | None = None) -> tuple:
    """log of a histogram over the bins from ``counts``: with one pseudo-count a bin, or
    with ``CALIBRATION_PRIOR`` pseudo-reads spread as ``prior`` (log, a histogram of more
    data) where the counts are few."""
    if prior is None:
        total = sum(counts) + len(counts)
        return tuple(math.log((n + 1) / total) for n in counts)
    total = sum(counts) + CALIBRATION_PRIOR
    return tuple(
        math.log((n + CALIBRATION_PRIOR * math.exp(p)) / total)
        for n, p in zip(counts, prior, strict=True)
    )


def _swapped(code: str, read: str, i: int, j: int) -> bool:
    """Whether the two characters of ``code`` before ``i`` are read swapped before ``j``."""
    if i < 2 or j < 2 or code[i - 1] == code[i - 2]:
        return False
    return code[i - 1] == read[j - 2] and code[i - 2] == read[j - 1]


def _scores(read: str, scores: Sequence[float]) -> list[float]:
    return list(scores) if len(scores) == len(read) else [UNKNOWN_SCORE] * len(read)


@functools.cache
def shipped_model(path: Path = DATA_FILE) -> ConfusionModel:
    """The confusion model of the table ``benchmarks/ocr_confusions.py`` wrote."""
    try:
        return ConfusionModel.from_counts(json.loads(path.read_text()))
    except (OSError, ValueError, KeyError) as e:
        raise ConfigError(f"{path}: not an OCR confusion table ({e})") from e
