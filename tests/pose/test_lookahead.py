"""The expected-trip score of where to look next (pose/lookahead.py)."""

import numpy as np

from pmnav_bt.pose.lookahead import commit, expected_trip


def test_committing_without_knowing_costs_the_wrong_guess_there_and_back():
    mass = np.array([0.5, 0.5])
    onward = np.array([[10.0], [30.0]])
    alike = np.array([[0], [0]])
    # Guess cluster 0's way (its wrong guess is the cheaper): 0.5 * 10 + 0.5 * 30 + 2 * 0.5 * 10.
    assert commit(mass, onward, alike)[0] == 30.0
    told_apart = np.array([[0], [1]])
    assert commit(mass, onward, told_apart)[0] == 20.0


def _three_clusters(between_01: float):
    # Clusters A, B (mirror images, 0.4 each) and C (0.2). Place 0, 2 m away, tells only C
    # apart; place 1, 10 m away, tells all three apart. The way on is 20 m from anywhere.
    reach = np.array([2.0, 10.0])
    between = np.array([[0.0, between_01], [between_01, 0.0]])
    sees = np.array([[0, 0], [0, 1], [1, 2]])
    onward = np.full((3, 2), 20.0)
    mass = np.array([0.4, 0.4, 0.2])
    usable = np.array([True, True])
    return expected_trip(reach, between, sees, onward, mass, usable, fix_share=0.85)


def test_a_near_look_that_leaves_mirror_images_loses_to_one_that_tells_all():
    # Place 1 lies the other way (12 m from place 0): looking at 0 first leaves A and B to
    # tell apart with another 12 m drive, worse than going to place 1 straight away.
    trip = _three_clusters(12.0)
    assert trip[1] < trip[0]
    assert np.isclose(trip[1], 10.0 + 20.0)
    # (The drive there plus the mean way on, as if any look told all, gives place 0
    # 2 + 20 and place 1 10 + 20: the near look that leaves A and B alike.)


def test_a_near_look_on_the_way_to_the_telling_place_costs_nothing_more():
    # Place 1 lies beyond place 0 (8 m on): looking at 0 on the way is as good.
    trip = _three_clusters(8.0)
    assert trip[0] <= trip[1] + 1e-9


def test_places_that_tell_nothing_or_lie_in_a_wall_are_never_chosen():
    reach = np.array([1.0, 3.0, 5.0])
    between = np.abs(reach[:, None] - reach[None, :])
    sees = np.array([[0, 0, 0], [0, -1, 1]])  # place 0 alike, place 1 a wall under B
    onward = np.full((2, 3), 10.0)
    mass = np.array([0.5, 0.5])
    trip = expected_trip(reach, between, sees, onward, mass, np.ones(3, bool), fix_share=0.85)
    assert np.isinf(trip[0]) and np.isinf(trip[1]) and np.isfinite(trip[2])
    # ... nor places already looked from.
    used = np.array([True, True, False])
    trip = expected_trip(reach, between, sees, onward, mass, used, fix_share=0.85)
    assert np.isinf(trip).all()
