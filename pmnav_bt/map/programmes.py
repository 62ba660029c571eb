"""What rooms a hospital, a school and an office floor hold: the generator's room programmes.

A *programme* is what an architect's brief lists for one building type: the corridor and
lobby widths, how deep the rooms behind the corridor walls are, and, per department, the
functions of its rooms with the width each takes along the corridor wall (its door pitch).
:mod:`pmnav_bt.map.functional` lays corridors out and walks their walls, drawing rooms
from these tables. The numbers are from practice:

- **Corridors.** Hospital corridors carry beds and trolleys side by side: 2.4-3.0 m (US
  guidance asks 8 ft, 2.44 m, where patients are moved in beds). School corridors carry a
  class change: 2.0-3.0 m. Office corridors carry people only: 1.5-2.0 m (1.5 m lets a
  wheelchair turn, 1.8 m lets two pass).
- **Room widths along the wall** (the door pitch): a consulting room 3.2-4.0 m, a six-bed
  bay 6.5-8 m, a single side room 3.4-4 m; a classroom 7-9 m (55-60 m2, 7 m deep), a
  science lab 9-11 m; a cellular office 2.7-3.6 m (two or three 1.35-1.5 m planning-grid
  modules), a meeting room 4-6 m. Nothing is narrower than 2.4 m, so every door (1.16 m
  with its frame) keeps room for its sign plate beside it.
- **Names** are what the people there call the rooms, with the aliases visitors use
  (``Radiology`` / ``X-ray``); a function that repeats is numbered (``Consulting Room 4``,
  ``Bay 2``) or named after the room's number (``Classroom 2.04``, ``Office 117``).
"""

from __future__ import annotations

from dataclasses import dataclass

# A room's name template may hold {n} (a counter per function), {code} (the room's number,
# given later by the numbering scheme) and {dept} (the department's title).


@dataclass(frozen=True)
class Function:
    """One kind of room: its name template, its width along the wall, its aliases and what
    its sign says after the room number (``sign=""``: the number alone)."""

    name: str
    widths: tuple[float, float]
    aliases: tuple[str, ...] = ()
    sign: str | None = None  # None: the name


@dataclass(frozen=True)
class Department:
    """A run of corridor walls with one purpose (a ward, the outpatients, a science wing).

    ``generic`` rooms repeat (one is drawn uniformly each time); each of ``once`` appears
    at most once in the department, drawn with probability ``p_once`` while some are left;
    ``title`` (may hold {ward}) is signed at the department's entrance when not empty.
    """

    title: str
    generic: tuple[Function, ...]
    once: tuple[Function, ...] = ()
    p_once: float = 0.3


@dataclass(frozen=True)
class Programme:
    """A building type: widths (m), room depth behind a wall (m), departments, services."""

    kind: str
    corridor: tuple[float, float]  # corridor width range
    lobby: tuple[float, float]  # entrance lobby width range
    room_depth: float  # rooms behind a wall are this deep: corridors keep 2x this apart
    main: Department  # the lobby and the main corridor
    wings: tuple[Department, ...]  # drawn for the wings, without repeats while they last
    core: Department  # the inner walls of a ring (the building's core)
    service: tuple[Function, ...]  # toilets, stores ...: anywhere, with p_service
    p_service: float
    reception: str  # the name of the desk in the lobby
    lift: str  # "Lift" or "Elevator"


def _f(name: str, lo: float, hi: float, *aliases: str, sign: str | None = None) -> Function:
    return Function(name, (lo, hi), tuple(aliases), sign)


_TOILETS = _f("Toilets", 2.4, 3.2, sign="Toilets")
_ACCESSIBLE = _f("Accessible Toilet", 2.4, 2.8, sign="Accessible WC")
_STORE = _f("Store {code}", 2.4, 3.0, sign="Store")
_CLEANER = _f("Cleaner's Cupboard", 2.4, 2.6, sign="Cleaner")

HOSPITAL = Programme(
    kind="hospital",
    corridor=(2.4, 3.0),
    lobby=(5.0, 7.0),
    room_depth=5.0,
    main=Department(
        "",
        generic=(_f("Consulting Room {n}", 3.2, 4.0, sign=""),),
        once=(
            _f("Radiology", 6.0, 9.0, "X-ray", "Imaging"),
            _f("Pharmacy", 5.0, 8.0, "Dispensary"),
            _f("Blood Tests", 4.0, 6.0, "Phlebotomy"),
            _f("Patient Advice", 3.0, 4.0, "PALS"),
            _f("Medical Records", 4.0, 6.0),
            _f("Cafe", 6.0, 9.0, "Coffee Shop"),
            _f("Chapel", 4.0, 6.0, "Multi-Faith Room", "Prayer Room"),
            _f("Cashier", 3.0, 4.0),
        ),
        p_once=0.45,
    ),
    wings=(
        Department(
            "Ward {ward}",
            generic=(
                _f("{dept} Bay {n}", 6.5, 8.0, sign="Bay {n}"),
                _f("{dept} Side Room {n}", 3.4, 4.0, sign="Side Room {n}"),
            ),
            once=(
                _f("{dept} Nurses' Station", 4.0, 5.0, sign="Nurses' Station"),
                _f("{dept} Sluice", 2.6, 3.2, sign="Sluice"),
                _f("{dept} Clean Utility", 2.6, 3.2, sign="Clean Utility"),
                _f("{dept} Treatment Room", 3.5, 4.2, sign="Treatment Room"),
                _f("{dept} Day Room", 5.0, 6.0, sign="Day Room"),
                _f("{dept} Ward Manager", 2.8, 3.4, sign="Ward Manager"),
            ),
            p_once=0.35,
        ),
        Department(
            "Outpatients",
            generic=(
                _f("Consulting Room {n}", 3.2, 4.0, sign=""),
                _f("Examination Room {n}", 3.2, 4.0, sign=""),
            ),
            once=(
                _f("Audiology", 4.0, 6.0, "Hearing Clinic"),
                _f("Eye Clinic", 5.0, 7.0, "Ophthalmology"),
                _f("Dermatology", 4.0, 6.0, "Skin Clinic"),
                _f("Fracture Clinic", 5.0, 7.0, "Orthopaedics"),
            ),
        ),
        Department(
            "Imaging",
            generic=(_f("X-Ray Room {n}", 4.5, 6.0, sign="X-Ray {n}"),),
            once=(
                _f("CT Scanner", 6.0, 8.0, "CT"),
                _f("MRI Scanner", 7.0, 9.0, "MRI"),
                _f("Ultrasound", 3.6, 4.5, "Sonography"),
                _f("Reporting Room", 3.0, 4.0),
                _f("Changing Cubicles", 3.0, 4.0),
            ),
            p_once=0.5,
        ),
        Department(
            "Ward {ward}",
            generic=(
                _f("{dept} Bay {n}", 6.5, 8.0, sign="Bay {n}"),
                _f("{dept} Side Room {n}", 3.4, 4.0, sign="Side Room {n}"),
            ),
            once=(
                _f("{dept} Nurses' Station", 4.0, 5.0, sign="Nurses' Station"),
                _f("{dept} Sluice", 2.6, 3.2, sign="Sluice"),
                _f("{dept} Treatment Room", 3.5, 4.2, sign="Treatment Room"),
                _f("{dept} Linen Store", 2.4, 2.8, sign="Linen"),
            ),
            p_once=0.35,
        ),
        Department(
            "Physiotherapy",
            generic=(_f("Treatment Room {n}", 3.4, 4.2, sign=""),),
            once=(
                _f("Gym", 8.0, 11.0, "Physio Gym"),
                _f("Hydrotherapy", 8.0, 10.0, "Hydrotherapy Pool"),
                _f("Occupational Therapy", 5.0, 7.0, "OT"),
            ),
            p_once=0.4,
        ),
    ),
    core=Department(
        "",
        generic=(_STORE, _f("Equipment Store {code}", 2.4, 3.4, sign="Equipment")),
        once=(
            _f("Staff Room", 4.0, 6.0, "Staff Rest Room"),
            _f("Sluice", 2.6, 3.2, "Dirty Utility"),
            _f("Disposal Hold", 2.4, 3.0),
            _f("Plant Room", 3.0, 4.0),
        ),
        p_once=0.5,
    ),
    service=(_TOILETS, _ACCESSIBLE, _STORE, _CLEANER),
    p_service=0.15,
    reception="Main Reception",
    lift="Lift",
)

SCHOOL = Programme(
    kind="school",
    corridor=(2.0, 3.0),
    lobby=(4.5, 6.0),
    room_depth=7.0,
    main=Department(
        "",
        generic=(_f("Classroom {code}", 7.0, 9.0, sign=""),),
        once=(
            _f("School Office", 4.0, 6.0, "Main Office"),
            _f("Head Teacher's Office", 3.4, 4.2, "Head's Office", "Principal", sign="Head"),
            _f("Library", 12.0, 16.0, "Media Centre", "LRC"),
            _f("Staff Room", 6.0, 8.0, "Staffroom"),
            _f("Medical Room", 3.0, 4.0, "First Aid", "Sick Bay"),
            _f("Hall", 14.0, 18.0, "Assembly Hall", "Main Hall"),
            _f("Canteen", 12.0, 16.0, "Dining Hall"),
            _f("Reprographics", 3.0, 4.0, "Print Room"),
        ),
        p_once=0.4,
    ),
    wings=(
        Department(
            "Science",
            generic=(_f("Science Lab {n}", 9.0, 11.0, "Lab {n}"),),
            once=(_f("Prep Room", 3.0, 4.0, "Science Prep"), _f("Chemical Store", 2.4, 3.0)),
        ),
        Department(
            "Humanities",
            generic=(_f("Classroom {code}", 7.0, 9.0, sign=""),),
            once=(_f("Learning Support", 4.0, 6.0, "SEN Room"), _f("Staff Office", 3.0, 4.0)),
            p_once=0.2,
        ),
        Department(
            "Arts",
            generic=(_f("Practice Room {n}", 2.6, 3.2),),
            once=(
                _f("Music Room", 8.0, 10.0, "Music"),
                _f("Art Room", 8.0, 11.0, "Art Studio"),
                _f("Drama Studio", 10.0, 13.0, "Drama"),
                _f("Kiln Room", 2.6, 3.2),
            ),
            p_once=0.45,
        ),
        Department(
            "Technology",
            generic=(_f("Computer Room {n}", 8.0, 9.5, "ICT {n}"),),
            once=(
                _f("Design Workshop", 10.0, 12.0, "D&T", "Technology Workshop"),
                _f("Food Room", 8.0, 10.0, "Food Technology"),
                _f("Server Room", 2.4, 3.0),
            ),
            p_once=0.4,
        ),
        Department(
            "Sports",
            generic=(_f("Changing Room {n}", 4.0, 6.0, "Changing {n}"),),
            once=(
                _f("Sports Hall", 16.0, 20.0, "Gym", "Gymnasium"),
                _f("PE Office", 3.0, 3.6),
                _f("Equipment Store", 3.0, 4.0),
            ),
            p_once=0.45,
        ),
    ),
    core=Department(
        "",
        generic=(_f("Classroom {code}", 7.0, 9.0, sign=""),),
        once=(_f("Toilets Block", 4.0, 5.0, "Main Toilets"),),
        p_once=0.2,
    ),
    service=(
        _f("Boys' Toilets", 3.0, 4.0, sign="Boys"),
        _f("Girls' Toilets", 3.0, 4.0, sign="Girls"),
        _ACCESSIBLE,
        _STORE,
    ),
    p_service=0.12,
    reception="Reception",
    lift="Lift",
)

CITIES = (
    "Oslo", "Lisbon", "Vienna", "Dublin", "Prague", "Madrid", "Berlin", "Tokyo",
    "Nairobi", "Lima", "Quito", "Seoul", "Cairo", "Athens", "Bergen", "Porto",
)  # fmt: skip
# meeting rooms are named after these cities, each once per building

OFFICE = Programme(
    kind="office",
    corridor=(1.5, 2.0),
    lobby=(4.5, 5.5),
    room_depth=4.5,
    main=Department(
        "",
        generic=(
            _f("Office {code}", 2.7, 3.6, sign=""),
            _f("Office {code}", 2.7, 3.6, sign=""),
            _f("Meeting Room {city}", 4.0, 6.0, "{city}", sign="{city}"),
        ),
        once=(
            _f("Boardroom", 6.0, 8.0, "Board Room"),
            _f("Human Resources", 4.0, 6.0, "HR"),
            _f("Finance", 4.0, 6.0, "Accounts"),
            _f("IT Support", 3.0, 4.0, "Helpdesk"),
            _f("Post Room", 2.7, 3.6, "Mail Room"),
            _f("Wellbeing Room", 2.7, 3.6, "First Aid Room"),
        ),
        p_once=0.25,
    ),
    wings=(
        Department(
            "",
            generic=(
                _f("Office {code}", 2.7, 3.6, sign=""),
                _f("Office {code}", 2.7, 3.6, sign=""),
                _f("Meeting Room {city}", 4.0, 6.0, "{city}", sign="{city}"),
            ),
            once=(_f("Quiet Room", 2.7, 3.6), _f("Legal", 4.0, 6.0, "Legal Department")),
            p_once=0.15,
        ),
    ),
    core=Department(
        "",
        generic=(_STORE, _f("Phone Room {n}", 2.4, 2.7)),
        once=(
            _f("Kitchen", 3.6, 5.0, "Kitchenette", "Pantry"),
            _f("Print Room", 2.7, 3.6, "Copy Room", "Printers"),
            _f("Server Room", 2.7, 3.6, "Comms Room"),
            _f("Stationery Store", 2.4, 3.0),
            _TOILETS,
            _ACCESSIBLE,
        ),
        p_once=0.55,
    ),
    service=(_TOILETS, _f("Kitchen", 3.6, 5.0, "Kitchenette", "Pantry"), _CLEANER),
    p_service=0.1,
    reception="Reception",
    lift="Lift",
)

PROGRAMMES: dict[str, Programme] = {p.kind: p for p in (HOSPITAL, SCHOOL, OFFICE)}
