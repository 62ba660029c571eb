"""Which room or landmark a read sign names, tolerant of OCR errors in words, strict in numbers.

Every entity of the building is known by keys: its sign text, the sign text without its
leading room number, its name and aliases (all normalised to lower-case letters and
digits). A reading matches a key by string similarity (difflib), or as a fragment of it
(a sign cut by the image border), under one hard rule: **the digits must agree**. The
digit sequence of the reading must equal the key's, so "108 Pharmacy" never matches
"102 Pharmacy", and a bare number matches only the room whose sign starts with exactly
that number. Letters commonly read for digits inside a number ("1O5", "l12") are mapped
to digits first; a reading that then matches nothing is tried as read (a lettered room
number, "D103") and with its leading digit as a look-alike letter ("0103" for "D103",
when only one such reading names an entity). Digits read with a low recogniser score are
not trusted at all: such a reading matches nothing. The best entity must beat the
runner-up by a margin, else the reading is ambiguous and matches nothing.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Sequence
from dataclasses import dataclass

from pmnav_bt.map.building import Building
from pmnav_bt.map.signage import split_number
from pmnav_bt.seams import Entity

MIN_SIMILARITY = 0.78  # difflib ratio for a fuzzy word match
MIN_FRAGMENT = 4  # characters of a key a cut-off reading must show
MARGIN = 0.1  # the best entity must beat the runner-up by this much
MIN_DIGIT_SCORE = 0.85  # recogniser score a line with digits needs

_NUMBER = re.compile(r"^[A-Za-z]?\d+[A-Za-z]?$")
# Letters an OCR model reads for digits, fixed only inside tokens that are mostly digits.
_DIGIT_LOOKALIKES = str.maketrans({"O": "0", "o": "0", "D": "0", "I": "1", "l": "1", "|": "1"})
# Digits an OCR model reads for the letter of a lettered room number ("0103" for "D103"),
# tried only when a reading matches nothing as read.
_LETTER_LOOKALIKES = {"0": "doq", "1": "il", "2": "z", "4": "a", "5": "s", "6": "g", "8": "b"}


def normalise(text: str) -> str:
    """Lower-case letters and digits only."""
    return re.sub(r"[^0-9a-z]", "", text.casefold())


def digits(key: str) -> str:
    return "".join(c for c in key if c.isdigit())


def fix_numbers(text: str) -> str:
    """Map look-alike letters to digits in tokens that are mostly digits ("1O5" -> "105")."""
    out = []
    for tok in text.split():
        n_digits = sum(c.isdigit() for c in tok)
        if n_digits >= 2 and n_digits >= len(tok) - 1:
            tok = tok.translate(_DIGIT_LOOKALIKES)
        out.append(tok)
    return " ".join(out)


def lettered(text: str) -> list[str]:
    """The readings of ``text`` with the first digit of one all-digit token (3 or more
    digits) read as a look-alike letter: the wing letter of "D103" is often read "0"."""
    toks = text.split()
    out = []
    for i, tok in enumerate(toks):
        if len(tok) >= 3 and tok.isdigit():
            for c in _LETTER_LOOKALIKES.get(tok[0], ""):
                out.append(" ".join([*toks[:i], c + tok[1:], *toks[i + 1 :]]))
    return out


def sign_number(sign_text: str) -> str | None:
    """The room number a sign starts with ("117 One-Stop ..." -> "117"), if any."""
    words = sign_text.split()
    return words[0].casefold() if words and _NUMBER.match(words[0]) else None


@dataclass(frozen=True)
class Match:
    """A reading matched to an entity: how similar (0..1), and the key it matched."""

    entity: Entity
    score: float
    key: str


class SignMatcher:
    """Matches sign readings to the rooms and landmarks of one building."""

    def __init__(self, building: Building):
        self.keys: list[tuple[str, Entity]] = []
        self._numbers: dict[Entity, str] = {}
        self._sign_numbers: dict[str, list[Entity]] = {}  # "117" -> entities whose signs start so
        for r in building.rooms:
            self._add(Entity.room(r.id), r.sign_text, r.name, *r.aliases)
        for lm in building.landmarks:
            self._add(Entity.landmark(lm.id), lm.sign or lm.display_name, lm.name, *lm.aliases)

    def _add(self, entity: Entity, sign: str, *names: str) -> None:
        texts = [sign, *names]
        number = split_number(sign)[0].casefold()
        if number:
            self._sign_numbers.setdefault(number, []).append(entity)
        num = sign_number(sign)
        if num is not None:
            self._numbers[entity] = digits(num)
        if num is not None:  # the number alone (the rest unread) and the rest alone
            texts += [num, sign.split(None, 1)[1] if " " in sign else ""]
        seen = set()
        for t in texts:
            k = normalise(t)
            if k and k not in seen:
                seen.add(k)
                self.keys.append((k, entity))

    def sign_text_of(self, entity: Entity) -> str:
        """The first key registered for ``entity`` (its sign text, normalised)."""
        return next(k for k, e in self.keys if e == entity)

    @staticmethod
    def trusted(lines: Sequence[tuple[str, float]]) -> bool:
        """False when a line shows digits read with a low recogniser score."""
        return not any(digits(normalise(fix_numbers(t))) and s < MIN_DIGIT_SCORE for t, s in lines)

    def numbered(self, text: str) -> Entity | None:
        """The one entity whose sign starts with the room number ``text`` starts with, when
        ``text`` also has a name: for a reading that matched nothing, the room whose sign
        reads differently from the map ("117 Quiet Room" where the map says "117
        Pharmacy"). None without a number, a name, or a single owner of the number."""
        number, name = split_number(fix_numbers(text))
        owners = self._sign_numbers.get(number.casefold(), []) if number and name else []
        return owners[0] if len(owners) == 1 else None

    def match(self, lines: Sequence[tuple[str, float]]) -> Match | None:
        """The entity that the lines of one sign (text, recogniser score) name, or None.

        The lines are matched together; failing that (a number cut by the image border),
        the lines without digits are, and the digits read must then be a part of the
        matched sign's number.
        """
        if not self.trusted(lines):
            return None  # digits we do not trust: never guess a number
        whole = self._match_whole(" ".join(t for t, _ in lines))
        if whole is not None or len(lines) < 2:
            return whole
        read_digits = [digits(normalise(fix_numbers(t))) for t, _ in lines]
        words = [t for (t, _), d in zip(lines, read_digits, strict=True) if not d]
        part = self._match_key(normalise(" ".join(words))) if words else None
        if part is None:
            return None
        number = self._numbers.get(part.entity, "")
        if all(d in number for d in read_digits if d):
            return Match(part.entity, 0.9 * part.score, part.key)
        return None

    def _match_whole(self, text: str) -> Match | None:
        """``text`` with look-alike letters in numbers read as digits ("1O5"); failing
        that, as read (a lettered number, "D103", is not "0103"); failing that, with a
        leading digit read as a look-alike letter ("0103"), when exactly one such reading
        names an entity."""
        fixed = fix_numbers(text)
        for reading in (fixed, text):
            m = self._match_key(normalise(reading))
            if m is not None:
                return m
        found: dict[Entity, Match] = {}
        for reading in lettered(fixed):
            m = self._match_key(normalise(reading))
            if m is not None and m.entity not in found:
                found[m.entity] = Match(m.entity, 0.9 * m.score, m.key)
        return next(iter(found.values())) if len(found) == 1 else None

    def _match_key(self, key: str) -> Match | None:
        if not key:
            return None
        best: dict[Entity, Match] = {}
        for k, entity in self.keys:
            score = _similarity(key, k)
            if score > 0 and (entity not in best or score > best[entity].score):
                best[entity] = Match(entity, score, k)
        ranked = sorted(best.values(), key=lambda m: -m.score)
        if not ranked or ranked[0].score < MIN_SIMILARITY:
            return None
        if len(ranked) > 1 and ranked[0].score - ranked[1].score < MARGIN:
            return None
        return ranked[0]


def _similarity(reading: str, key: str) -> float:
    """Similarity of a normalised reading to a normalised key; 0 when the digits disagree."""
    if digits(reading) != digits(key):
        return 0.0
    if reading == key:
        return 1.0
    ratio = difflib.SequenceMatcher(None, reading, key, autojunk=False).ratio()
    # A fragment (a sign cut by the border, a line the reader missed): the reading is a
    # near-exact part of the key.
    if len(reading) >= MIN_FRAGMENT and len(reading) < len(key):
        sm = difflib.SequenceMatcher(None, key, reading, autojunk=False)
        m = sm.find_longest_match(0, len(key), 0, len(reading))
        if m.size >= len(reading) - 1:
            part = 0.8 + 0.2 * len(reading) / len(key)
            ratio = max(ratio, part)
    return ratio
