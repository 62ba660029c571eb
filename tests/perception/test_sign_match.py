"""Sign text -> entity: by likelihood under the OCR confusion model, never by a guess."""

from __future__ import annotations

import math

import pytest
from sign_kit import SURE, corridor, read

from pmnav_bt.perception.sign_match import SignMatcher, decide, sign_number
from pmnav_bt.seams import Entity


@pytest.fixture(scope="module")
def matcher(fig2):
    return SignMatcher(fig2)


def test_exact_and_ocr_noisy_names(matcher):
    assert matcher.match([("102", 1.0), ("Pharmacy", 1.0)]).entity == Entity.room("room2")
    assert matcher.match([("Registraton", 0.9)]).entity == Entity.room("room1")
    assert matcher.match([("Elerator A", 0.95)]).entity == Entity.landmark("elevator1")
    assert matcher.match([("Reception Desk", 1.0)]).entity == Entity.landmark("reception")


def test_sign_number_reads_every_scheme():
    assert [sign_number(t) for t in ("117 Lab", "1G", "2.04 Radiology", "L2-204 X", "B117")] == [
        "117",
        "1g",
        "2.04",
        "l2-204",
        "b117",
    ]
    assert sign_number("Pharmacy") is None


# (plate, its one-character neighbour the building also holds, index of the character)
NEIGHBOURS = {
    "B/8": ("B117", "8117", 0),
    "O/0": ("O112", "0112", 0),
    "I/1": ("I12", "112", 0),
    "l/1": ("l12", "112", 0),
    "S/5": ("S204", "5204", 0),
    "Z/2": ("Z21", "221", 0),
    "G/6": ("1G", "16", 1),
    "letter": ("1C", "1G", 1),
    "4/1": ("104", "101", 2),  # once taken: a "104" plate read "101" named room 101
}


@pytest.mark.parametrize("kind", NEIGHBOURS)
def test_a_one_character_neighbour_is_never_taken(kind):
    """The plate shows ``a``; the building also holds ``b``, one confusion away. Read as
    ``b`` with the differing character hesitated over, the reading names neither; read as
    ``b`` with every character sure, it is ``b`` (the reading is not thrown away)."""
    a, b, i = NEIGHBOURS[kind]
    m = SignMatcher(corridor(a, b, "3.99"))
    ra, rb = Entity.room("r0"), Entity.room("r1")
    unsure = {i}
    assert m.match(read(b.casefold(), unsure)) is None, kind
    sure = m.match(read(b))
    if kind == "O/0":  # the reader reads every O as 0 (the table): a sure "0" is no proof
        assert sure is None
    else:
        assert sure.entity == rb, kind
    got = m.match(read(a))
    assert got is None or got.entity == ra, kind


def test_an_ambiguous_read_is_not_a_sighting():
    """A reading one substitution from two codes the building holds, or from none, names
    nothing, however sure the recogniser is; so does a name several rooms share."""
    m = SignMatcher(corridor(*(f"1{c} Ward" for c in "ABCDEFG"), "2.04 Lab", "2.40 Lab"))
    assert m.match(read("2.44")) is None  # 2.04 or 2.40
    assert m.match(read("1H")) is None  # no 1H: a plate the map does not hold
    assert m.match([("Ward", SURE)]) is None  # seven wards
    ev = m.evidence(read("2.44"))
    lab = [ev.entities[Entity.room(r)] for r in ("r7", "r8")]
    assert abs(lab[0] - lab[1]) < 1.0  # the two are about as likely
    assert m.match(read("1C")).entity == Entity.room("r2")


def test_unsure_digits_are_not_trusted(matcher):
    assert matcher.match(read("110", {0, 1, 2}, score=0.3)) is None
    assert matcher.match(read("110")).entity == Entity.room("room10")


def test_ambiguous_and_unknown_readings_match_nothing(matcher):
    assert matcher.match([("Consulting Room", 1.0)]) is None  # rooms 5 to 14 alike
    assert matcher.match([("194 abirature", 0.9)]) is None
    assert matcher.match([("Exit", 1.0)]) is None


def test_a_sign_cut_by_the_border(matcher):
    assert matcher.match([("harmacy", 0.95)]).entity == Entity.room("room2")
    # The number's first digit cut off: the name still tells.
    assert matcher.match([("02", 0.99), ("Pharmacy", 0.99)]).entity == Entity.room("room2")


def test_lettered_room_numbers_and_their_wing_letter_read_as_a_digit():
    """The sign-sparse family's wings are lettered (A101, D103): a sure "D103" is D103;
    its wing letter read "0" with hesitation names nothing (D103 or 0103?), and a wing
    the building does not have names nothing."""
    from pmnav_bt.map.generate import generate_sign_sparse

    b = generate_sign_sparse(0)
    m = SignMatcher(b)
    assert m.scheme.name == "B117"
    by_sign = {r.sign_text: Entity.room(r.id) for r in b.rooms}
    assert m.match(read("D103")).entity == by_sign["D103"]
    assert m.match(read("8102", {0})).entity == by_sign["B102"]  # no 8102: B read as 8
    assert m.match(read("1103")) is None  # "I103" / "L103": no such wing
    assert m.match(read("D109")) is None


def test_a_code_read_in_two_words_at_its_separator_is_the_code():
    """The reader cuts "L1-116B" at its hyphen ("L1-" "116B", "L1 116B"): the parts joined
    by the building's own separator (parsed from its codes) are the code."""
    m = SignMatcher(corridor("L1-114B", "L1-116A", "L1-116B", "L1-118"))
    assert m.scheme.separators == frozenset("-")
    for text in ("L1- 116B", "L1 116B", "L1-116B"):
        found = m.match(read(text))
        assert found is not None and found.entity == Entity.room("r2"), text
    assert m.match(read("L1 116")) is None  # 116A or 116B: the suffix not read
    assert m.match(read("L2 116B")) is None  # another level's plate


def test_decide_needs_the_margin_over_the_runner_up_and_the_unknown_plate():
    m = SignMatcher(corridor("2.04", "2.40"))
    ev = m.evidence(read("2.04"))
    best = decide(ev)
    assert best.entity == Entity.room("r0") and best.score > 0.9
    # a prior against it as strong as the reading's evidence leaves it open
    gap = ev.entities[Entity.room("r0")] - ev.entities[Entity.room("r1")]
    assert decide(ev, {Entity.room("r0"): -gap}) is None


def test_a_plate_another_goes_on_past_is_never_taken_on_the_doors_spacing():
    """'hardware' is one room's whole plate and the start of another's, 'hardware 2' (the
    office of Open-RMF's demos): read 'hardware', the reader may have dropped the '2', so
    the read names neither, however strongly the doors' spacing (the plate memory's prior)
    favours one; read 'hardware 2', it names that room, even against the spacing."""
    m = SignMatcher(corridor("hardware", "hardware 2", "main"))
    short, longer = Entity.room("r0"), Entity.room("r1")
    spacing = {short: 0.0, longer: math.log(0.05)}  # the spacing's strongest preference
    assert decide(m.evidence(read("hardware")), spacing) is None
    assert decide(m.evidence(read("hardware")), {short: math.log(0.05), longer: 0.0}) is None
    assert decide(m.evidence(read("hardware 2")), spacing).entity == longer
    # a read that showed the '2' settles the plate's other reads
    both = m.evidence(read("hardware")).add(m.evidence(read("hardware 2")))
    assert decide(both, spacing).entity == longer
    assert m.match(read("main")).entity == Entity.room("r2")  # no other plate goes on past it
    # Two plates alike, each read whole: the spacing tells them apart as before.
    twins = SignMatcher(corridor("Stairs", "Stairs", "main"))
    assert decide(twins.evidence(read("Stairs")), spacing).entity == short
