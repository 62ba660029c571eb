"""Sign text -> entity: tolerant of OCR errors in words, strict in numbers."""

from __future__ import annotations

import pytest

from pmnav_bt.perception.sign_match import SignMatcher, fix_numbers, sign_number
from pmnav_bt.seams import Entity


@pytest.fixture(scope="module")
def matcher(fig2):
    return SignMatcher(fig2)


def test_exact_and_ocr_noisy_names(matcher):
    assert matcher.match([("102", 1.0), ("Pharmacy", 1.0)]).entity == Entity.room("room2")
    assert matcher.match([("Registraton", 0.9)]).entity == Entity.room("room1")
    assert matcher.match([("Elerator A", 0.95)]).entity == Entity.landmark("elevator1")
    assert matcher.match([("Reception Desk", 1.0)]).entity == Entity.landmark("reception")


def test_look_alike_letters_in_numbers(matcher):
    assert fix_numbers("1O5 Lab") == "105 Lab"
    assert matcher.match([("1O5", 0.95)]).entity == Entity.room("room5")


def test_lettered_room_numbers_and_their_wing_letter_read_as_a_digit():
    """The sign-sparse family's wings are lettered (A101, D103): "D" is a look-alike of
    "0", so a perfect reading of "D103" used to be mapped to "0103" and match nothing."""
    from pmnav_bt.map.generate import generate_sign_sparse

    m = SignMatcher(generate_sign_sparse(0))
    by_sign = {r.sign_text: Entity.room(r.id) for r in generate_sign_sparse(0).rooms}
    assert m.match([("D103", 0.95)]).entity == by_sign["D103"]
    assert m.match([("0103", 0.95)]).entity == by_sign["D103"]  # the wing letter read "0"
    assert m.match([("8102", 0.95)]).entity == by_sign["B102"]
    assert m.match([("0103", 0.95)]).score < m.match([("D103", 0.95)]).score
    assert m.match([("1103", 0.95)]) is None  # "I103" / "L103": no such wing
    assert m.match([("D109", 0.95)]) is None  # the digits still must agree


def test_a_misread_digit_never_names_another_room(fig2, matcher):
    """Every one-digit misreading of every room number (alone and with the room's name)
    names nothing, or exactly the room whose sign carries the misread number."""
    by_number = {sign_number(r.sign_text): r.id for r in fig2.rooms if sign_number(r.sign_text)}
    checked = 0
    for r in fig2.rooms:
        num = sign_number(r.sign_text)
        rest = r.sign_text.split(None, 1)[1] if " " in r.sign_text else ""
        for i, ch in enumerate(num):
            for d in "0123456789":
                if d == ch:
                    continue
                wrong = num[:i] + d + num[i + 1 :]
                for lines in ([(wrong, 1.0)], [(wrong, 1.0), (rest, 1.0)]):
                    if not lines[-1][0]:
                        continue
                    m = matcher.match(lines)
                    checked += 1
                    assert m is None or (
                        len(lines) == 1 and m.entity == Entity.room(by_number[wrong])
                    ), (lines, m)
    assert checked > 100


def test_digits_read_with_a_low_score_are_not_trusted(matcher):
    assert matcher.match([("110", 0.66)]) is None
    assert matcher.match([("110", 0.99)]).entity == Entity.room("room10")


def test_ambiguous_and_unknown_readings_match_nothing(matcher):
    assert matcher.match([("Consulting Room", 1.0)]) is None  # rooms 5 to 14 alike
    assert matcher.match([("194 abirature", 0.9)]) is None
    assert matcher.match([("Exit", 1.0)]) is None


def test_a_sign_cut_by_the_border(matcher):
    assert matcher.match([("harmacy", 0.95)]).entity == Entity.room("room2")
    # The number's first digit cut off: the name still tells, the digits agree with it.
    assert matcher.match([("02", 0.99), ("Pharmacy", 0.99)]).entity == Entity.room("room2")
    # ... but a fragment of another room's number does not.
    assert matcher.match([("04", 0.99), ("Pharmacy", 0.99)]) is None
