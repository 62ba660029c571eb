"""The numbering scheme is parsed from a building's codes, not assumed."""

from __future__ import annotations

import pytest

from pmnav_bt.map.numbering import SCHEMES, parse_scheme, room_code, wing_letter


def codes_of(scheme: str) -> list[str]:
    return [
        room_code(scheme, f, n, wing_letter(w)) for f in (1, 2) for n in (1, 7, 12) for w in (0, 3)
    ]


@pytest.mark.parametrize(
    ("scheme", "prefixes", "suffixes", "separators", "digits"),
    [
        ("117", set(), set(), set(), (3, 3)),
        ("1G", set(), {"a", "d"}, set(), (1, 2)),
        ("2.04", set(), set(), {"."}, (3, 3)),
        ("L2-204", {"l"}, set(), {"-"}, (4, 4)),
        ("B117", {"a", "d"}, set(), set(), (3, 3)),
    ],
)
def test_each_scheme_is_recognised_with_its_parts(scheme, prefixes, suffixes, separators, digits):
    s = parse_scheme(codes_of(scheme))
    assert s.name == scheme
    assert (set(s.prefixes), set(s.suffixes), set(s.separators)) == (prefixes, suffixes, separators)
    assert s.digits == digits


def test_a_scheme_of_its_own_is_parsed_not_forced_into_a_known_one():
    s = parse_scheme(["W-12", "W-13", "E-02"])
    assert s.name == "mixed"
    assert set(s.prefixes) == {"w", "e"} and set(s.separators) == {"-"}
    assert s.shapes == {"a-99"}
    assert s.looks_like_code("W-14") and not s.looks_like_code("office")
    assert parse_scheme([]).name == "none" and not parse_scheme([]).looks_like_code("101")
    assert parse_scheme(["101", "2.04"]).name == "mixed"


def test_codes_as_ocr_reads_them_still_look_like_codes():
    """A look-alike letter where a digit belongs (and the other way round) still fits;
    words do not."""
    b117 = parse_scheme(codes_of("B117"))
    assert b117.looks_like_code("8117") and b117.looks_like_code("bll7")
    assert not b117.looks_like_code("pharmacy") and not b117.looks_like_code("wc")
    two = parse_scheme(codes_of("2.04"))
    assert two.looks_like_code("2,04") and two.looks_like_code("204")
    assert set(SCHEMES) == {parse_scheme(codes_of(k)).name for k in SCHEMES}


@pytest.mark.parametrize("scheme", SCHEMES)
def test_a_code_read_one_character_short_or_long_looks_like_a_code_but_does_not_parse(scheme):
    s = parse_scheme(codes_of(scheme))
    code = max(codes_of(scheme), key=len).casefold()
    assert s.parses(code)
    near = code + code[-1]  # the longest code with one character read twice
    assert s.looks_like_code(near) and not s.parses(near), near
    short = parse_scheme(["209", "210"])
    assert short.looks_like_code("79") and not short.parses("79") and short.parses("2O9")
