"""Which room or landmark a read sign names, by likelihood, never by a guess.

Buildings hold near-identical codes (``1A``..``1G``, ``2.04`` and ``2.40``, ``B117`` and
``8117`` as OCR reads it): a reading one character away from a room's code is a fair
reading of that room, but it may be a fair reading of its neighbour too. So a reading is
weighed against every entity of the building, and against a plate the building does not
hold, as log-likelihoods in one currency:

- **the code**: the building's numbering scheme is parsed from its codes
  (``map.numbering.parse_scheme``); the tokens of the reading that could be one of its
  codes are weighed with the OCR confusion model (``ocr_confusion``): the characters'
  confidences, and which characters the reader confuses, counted from data;
- **the name**: the words left are compared with the entity's name and aliases (difflib,
  tolerant of a letter or two; a fragment of a name cut by the image border counts):
  ``NAME_WEIGHT * (similarity - 1)``, no lower than what any text other than the name
  gets, so garbled words neither name nor veto a room;
- **none of them**: a code the building does not hold, read right (``P_UNKNOWN``), or
  words like no name (similarity ``NAME_NULL``).

A reading is a sighting of the best entity only when that entity is ``MARGIN`` times as
likely as all the others and none of them together (``decide``): otherwise it is ambiguous and
names nothing, and the tree looks again. A plate that is the start of another's
(``hardware`` and ``hardware 2``) is never taken from a read that stops where it ends: the
reader drops a word or a line as easily as it reads it, so only a read that shows the
rest tells them apart, and no prior may (``Evidence.unsettled``); a read that goes on past
the shorter plate with the longer one's words is not the shorter one's. ``Evidence`` from
several reads of one plate adds up (consistency), and a prior over entities (the order of
the doors along the corridor, ``grounders/plate_memory.py``) can settle what one read
leaves open.
"""

from __future__ import annotations

import difflib
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

from pmnav_bt.map.amenities import room_amenity
from pmnav_bt.map.building import Building
from pmnav_bt.map.numbering import NumberingScheme, parse_scheme
from pmnav_bt.map.signage import ROOM_NUMBER, split_number
from pmnav_bt.perception.ocr_confusion import ConfusionModel, shipped_model
from pmnav_bt.seams import Entity, EntityKind

MIN_FRAGMENT = 4  # characters of a name a cut-off reading must show
# A sighting is this many times as likely as any other entity and as an unknown plate: a
# posterior of at least 10/11 between the two.
MARGIN = math.log(10.0)
# Log-likelihood per unit of name similarity: a name 0.1 less similar is MARGIN less likely,
# so two names are told apart by a tenth of similarity.
NAME_WEIGHT = MARGIN / 0.1
# Similarity of words that name nothing of the building: with the margin, a name needs a
# similarity of 0.78 to be read.
NAME_NULL = 0.78 - 0.1
NAME_READ = NAME_NULL + MARGIN / NAME_WEIGHT  # (0.78) the similarity a name is read at
P_UNKNOWN = 0.02  # a code read right that the building does not hold (another floor, a sign)
SURE_DIGITS = 0.85  # recogniser score of digits a map update trusts (map_check.py)
# A character the confusion model's calibration finds read wrong this often at its
# confidence (below about 0.95: one in ten, against one in 400 at 0.999) leaves the read
# unsure: it may be a plate of the building, misread (``SignMatcher.unsure``).
UNSURE_P = 0.1
# A pictogram sighting (already above the reader's calibrated confidence) on a room the map
# says is not that amenity: a plate the map has wrong, or a misread; far less likely than a
# plate the building does not hold (P_UNKNOWN), so it never names such a room.
P_PICTOGRAM_ELSEWHERE = 1e-3

# Lines of one sign as read: (text, recogniser score) or (text, score, character scores).
Line = tuple[str, float] | tuple[str, float, Sequence[float]]


def normalise(text: str) -> str:
    """Lower-case letters and digits only."""
    return re.sub(r"[^0-9a-z]", "", text.casefold())


def sign_number(sign_text: str) -> str | None:
    """The room code a sign starts with (``"2.04 Radiology"`` -> ``"2.04"``), casefolded."""
    number, _ = split_number(sign_text)
    return number.casefold() or None


def entity_code(sign_text: str) -> str | None:
    """The code a sign carries: its leading room number, or the first word of it that is
    one (``"Stairs 2"`` -> ``"2"``), casefolded."""
    return next((w.casefold() for w in sign_text.split() if ROOM_NUMBER.match(w)), None)


@dataclass(frozen=True)
class Match:
    """A reading matched to an entity: its posterior probability (0..1) and how it was
    named (``code`` and/or ``name``)."""

    entity: Entity
    score: float
    key: str


@dataclass
class Evidence:
    """What reads of one plate say: log-likelihood of each entity and of an unknown plate.

    ``add`` combines the reads of one plate (independent reads multiply)."""

    entities: dict[Entity, float] = field(default_factory=dict)
    unknown: float = 0.0
    keys: dict[Entity, str] = field(default_factory=dict)
    code_read: bool = False  # a read showed a code: every room's code was weighed
    # Entities whose plates the words may be, one of them cut short (read "hardware": the
    # plate "hardware", or "hardware 2" with its "2" dropped): the reads tell them apart
    # or nothing does (``decide``).
    unsettled: frozenset[Entity] = frozenset()

    def add(self, other: Evidence) -> Evidence:
        ents = set(self.entities) & set(other.entities)
        return Evidence(
            {e: self.entities[e] + other.entities[e] for e in ents},
            self.unknown + other.unknown,
            {**other.keys, **self.keys},
            self.code_read or other.code_read,
            self.unsettled & other.unsettled,  # one read that told them apart settles it
        )


def decide(ev: Evidence, prior: Mapping[Entity, float] | None = None) -> Match | None:
    """The entity ``ev`` names, with ``prior`` (log, per entity; 0 where missing) added:
    the best, when it is ``MARGIN`` more likely than all the others and the unknown plate
    together (its posterior at least 10/11); else None (ambiguous)."""
    if not ev.entities:
        return None
    post = {e: ll + (prior.get(e, 0.0) if prior else 0.0) for e, ll in ev.entities.items()}
    best, ll = max(post.items(), key=lambda kv: kv[1])
    # The rest together: many rooms each a little likely are, together, a real doubt. With
    # no code read, one whose name is no likelier than an unknown plate's is one of those.
    rest = [ev.unknown] + [
        v for e, v in post.items() if e != best and (ev.code_read or v > ev.unknown)
    ]
    z = max(rest)
    rival = z + math.log(sum(math.exp(v - z) for v in rest))
    if ll - rival < MARGIN:
        return None
    if best in ev.unsettled and any(
        ev.entities[best] - ev.entities[e] < MARGIN for e in ev.unsettled - {best}
    ):
        return None  # the prior (where it stands) cannot tell whether a part went unread
    return Match(best, 1.0 / (1.0 + math.exp(rival - ll)), ev.keys.get(best, ""))


@dataclass(frozen=True)
class _Known:
    """One entity as signs name it: its code (casefolded) and its name keys."""

    entity: Entity
    code: str | None
    names: tuple[str, ...]
    plate: str = ""  # what its plate shows, code and words, normalised


class SignMatcher:
    """Weighs sign readings against the rooms and landmarks of one building."""

    def __init__(self, building: Building, model: ConfusionModel | None = None):
        self.model = model if model is not None else shipped_model()
        self.known: list[_Known] = []
        for r in building.rooms:
            self._add(Entity.room(r.id), r.sign_text, r.name, *r.aliases)
        for lm in building.landmarks:
            self._add(Entity.landmark(lm.id), lm.sign or lm.display_name, lm.name, *lm.aliases)
        self.scheme: NumberingScheme = parse_scheme(
            k.code for k in self.known if k.code and k.entity.kind == EntityKind.ROOM
        )
        self.amenities = {Entity.room(r.id): room_amenity(r) for r in building.rooms}

    def _add(self, entity: Entity, sign: str, *names: str) -> None:
        code = entity_code(sign)
        words = [w for w in sign.split() if w.casefold() != code]
        keys = []
        for t in (" ".join(words), *names):
            k = normalise(t)
            if k and k not in keys and not (code and k == normalise(code)):
                keys.append(k)
        self.known.append(_Known(entity, code, tuple(keys), normalise(sign)))

    @staticmethod
    def trusted(lines: Sequence[Line]) -> bool:
        """Whether every line showing digits was read with a recogniser score of at least
        ``SURE_DIGITS``: a plate that names nothing is written as a map update only then."""
        return not any(any(c.isdigit() for c in ln[0]) and ln[1] < SURE_DIGITS for ln in lines)

    def unsure(self, lines: Sequence[Line]) -> bool:
        """Whether a read that named nothing may still be a misread plate of the building,
        to be read again rather than taken for a plate it does not hold: a character read
        at a confidence the confusion model finds wrong at least ``UNSURE_P`` of the time,
        or a token that looks like one of the building's codes (within one character) but
        is not spelled as one ("79" or "2099" where every code is like "209")."""
        for text, scores in _tokens(lines):
            if any(self.model.p_misread(c) >= UNSURE_P for c in scores):
                return True
            if self.scheme.looks_like_code(text) and not self.scheme.parses(text):
                return True
        return False

    def numbered(self, text: str) -> Entity | None:
        """The one entity whose sign carries the code ``text`` starts with, when ``text``
        also has a name: for a reading that matched nothing, the room whose sign reads
        differently from the map ("117 Quiet Room" where the map says "117 Pharmacy").
        None without a code, a name, or a single owner of the code."""
        code, name = sign_number(text), split_number(text)[1]
        owners = [k.entity for k in self.known if code and k.code == code] if name else []
        return owners[0] if len(owners) == 1 else None

    def names_other(self, entity: Entity, text: str) -> bool:
        """Whether ``text`` (a plate read as ``entity``, by its code) carries words that are
        none of ``entity``'s names: a sign renamed since the map was drawn."""
        _, name = split_number(text)
        key = next((k for k in self.known if k.entity == entity), None)
        if key is None or not normalise(name):
            return False
        return max((_similarity(name, n) for n in key.names), default=0.0) < NAME_READ

    def match(self, lines: Sequence[Line]) -> Match | None:
        """The entity the lines of one sign name (see ``decide``), or None."""
        return decide(self.evidence(lines))

    def evidence(self, lines: Sequence[Line]) -> Evidence:
        """What the lines of one sign (top to bottom) say about each entity."""
        tokens = _tokens(lines)
        code_at, code_ll, code, scores = self._code_token(tokens)
        words = "".join(t for i, (t, _) in enumerate(tokens) if i not in code_at)
        name_null = NAME_WEIGHT * (NAME_NULL - 1.0) if words else 0.0
        unknown = name_null
        if code:
            unknown += math.log(P_UNKNOWN) + self.model.log_read_right(code, scores)
        ents, keys = {}, {}
        shown = normalise(words)
        unsettled: frozenset[Entity] = frozenset()
        for k in self.known:
            ll, how = 0.0, []
            if code:
                if k.code is None:  # its sign has no code: one read is a plate unknown
                    ll += 2 * math.log(P_UNKNOWN) + self.model.log_read_right(code, scores)
                else:
                    ll += code_ll[k.code]
                    how.append(k.code)
            if words:
                sim, key = max(((_similarity(words, n), n) for n in k.names), default=(0, ""))
                ll += max(NAME_WEIGHT * (sim - 1.0), name_null)
                if sim >= NAME_NULL:
                    how.append(key)
            ents[k.entity] = ll
            keys[k.entity] = " ".join(how)
        if shown and not code:
            unsettled = self._cut_short(shown)
            whole = any(o.plate == shown for o in self.known)  # another plate, read whole
            for k in self.known:
                if whole and k.plate and shown != k.plate and shown.startswith(k.plate):
                    ents[k.entity] = min(ents[k.entity], name_null)  # read on past its end
        return Evidence(ents, unknown, keys, code_read=bool(code), unsettled=unsettled)

    def _cut_short(self, shown: str) -> frozenset[Entity]:
        """The entities whose plate ``shown`` (a read's words, normalised) may be, when it
        may be the start of a longer plate: those plates and the one it is whole. Empty
        when no plate goes on past it (two plates alike are told apart by a prior)."""
        longer = {k.entity for k in self.known if k.plate.startswith(shown) and k.plate != shown}
        if not longer:
            return frozenset()
        return frozenset(longer | {k.entity for k in self.known if k.plate == shown})

    def pictogram_evidence(self, kind: str) -> Evidence:
        """What a plate showing the pictogram of ``kind`` ("toilet") says: each room the map
        says is a ``kind`` is as likely as the others (one such room is named; several are
        told apart by the rooms along the corridor, ``plate_memory``), a plate the
        building does not hold is ``P_UNKNOWN`` as likely, any other entity
        ``P_PICTOGRAM_ELSEWHERE``."""
        other = math.log(P_PICTOGRAM_ELSEWHERE)
        ents = {k.entity: (0.0 if self.amenities.get(k.entity) == kind else other)
                for k in self.known}
        keys = {e: kind for e, v in ents.items() if v == 0.0}
        return Evidence(ents, math.log(P_UNKNOWN), keys)

    def _code_token(
        self, tokens: list[tuple[str, list[float]]]
    ) -> tuple[tuple[int, ...], dict[str, float], str, list[float]]:
        """Which tokens (one, or two read apart: "L2 -204") are the plate's code: those
        that look like one of the building's codes and are likelier a misread code than
        words; the likeliest, with its log-likelihood under each code, and the code as it
        was read (its spelling, below) with its characters' confidences. () when none.

        Two tokens are the code's parts either side of a gap the reader put where the
        code has a separator ("L1-" and "116B" of "L1-116B": the reader cuts a word at a
        hyphen, and ``_tokens`` trims it off "L1-"), or read apart with nothing between:
        both are weighed, the separators being the building's own (``NumberingScheme``,
        parsed from its codes: none in a ``117`` building, ``-`` in an ``L2-204`` one)."""
        codes = {k.code for k in self.known if k.code}
        best: tuple[tuple[int, ...], dict[str, float], str, list[float]] = ((), {}, "", [])
        best_ll = -math.inf
        spans = [(i,) for i in range(len(tokens))]
        spans += [(i, i + 1) for i in range(len(tokens) - 1)]
        for span in spans:
            for text, sc in self._spellings([tokens[i] for i in span]):
                if not codes or not self.scheme.looks_like_code(text):
                    continue
                lls = {c: self.model.log_likelihood(text, sc, _compact(c)) for c in codes}
                ll = max(lls.values())
                has_digit = any(c.isdigit() for c in text)
                unknown = math.log(P_UNKNOWN) + self.model.log_read_right(text, sc)
                if not has_digit and ll < unknown:
                    continue  # a word, more likely than a misread code
                if ll > best_ll:
                    best, best_ll = (span, lls, text, sc), ll
        return best

    def _spellings(
        self, parts: list[tuple[str, list[float]]]
    ) -> list[tuple[str, list[float]]]:
        """The code ``parts`` (one token, or two read apart) may spell, with the characters'
        confidences: one token as read; two joined, and joined by each separator of the
        building's scheme (the separator, not read, at the confidence of its neighbours:
        the reader saw a gap there)."""
        text = "".join(t for t, _ in parts)
        sc = [s for _, scores in parts for s in scores]
        if len(parts) == 1:
            return [(text, sc)]
        (a, sa), (b, sb) = parts
        gap = min(sa[-1:] + sb[:1], default=0.9)
        return [(text, sc)] + [
            (a + sep + b, [*sa, gap, *sb]) for sep in sorted(self.scheme.separators)
        ]


def _compact(text: str) -> str:
    return text.casefold().replace(" ", "")


def _tokens(lines: Sequence[Line]) -> list[tuple[str, list[float]]]:
    """The reading's words, casefolded and trimmed of punctuation at their ends, each
    with its characters' confidences (the line's score where the reader gave none)."""
    out = []
    for line in lines:
        text, score = line[0], line[1]
        chars = list(line[2]) if len(line) > 2 else []  # type: ignore[misc]
        if len(chars) != len(text):
            chars = [score] * len(text)
        for m in re.finditer(r"\S+", text):
            tok, sc = m.group().casefold(), chars[m.start() : m.end()]
            lo = next((i for i, c in enumerate(tok) if c.isalnum()), len(tok))
            hi = next((i for i in range(len(tok), 0, -1) if tok[i - 1].isalnum()), 0)
            if lo < hi:
                out.append((tok[lo:hi], sc[lo:hi]))
    return out


def _similarity(reading: str, key: str) -> float:
    """Similarity of a normalised reading to a normalised name key (0..1)."""
    reading = normalise(reading)
    if reading == key:
        return 1.0
    ratio = difflib.SequenceMatcher(None, reading, key, autojunk=False).ratio()
    # A fragment (a sign cut by the border, a line the reader missed): the reading is a
    # near-exact part of the key.
    if len(reading) >= MIN_FRAGMENT and len(reading) < len(key):
        sm = difflib.SequenceMatcher(None, key, reading, autojunk=False)
        m = sm.find_longest_match(0, len(key), 0, len(reading))
        if m.size >= len(reading) - 1:
            ratio = max(ratio, 0.8 + 0.2 * len(reading) / len(key))
    return ratio
