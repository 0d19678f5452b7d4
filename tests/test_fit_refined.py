"""Rounded input, issue 16 (ninth session): the refined rounds after the merge pass, and the
joints' moves in an order-free sequence.

After the minimax merge pass (:meth:`_BatchFitter._minimax_merge_round`) the greedy chain
refit and the three-into-two resplit run once more (:meth:`_BatchFitter._refined_rounds`):
the ranges they tried before come back from a cache, and a range that failed is tried
only by the refinement (galvo_core.minimax) of the start cached for it. Whole-unit outlines
of three design cubics take fewer segments, within the bound and near the design."""

from __future__ import annotations

import numpy as np
from test_precision_minimax import fewer_than_without

from galvo_core import fit as fitmod

#: lens outlines (three design cubics) where the first rounds and the merge pass leave a
#: segment or two more than the refined rounds (or, now, as many)
LENSES = [
    (2312.981, 0.049, 1499.176, 460.948, 0.394, 0.53, 47.419),
    (15261.495, 0.553, 606.262, 545.75, 0.411, 0.534, -44.274),
    (12727.085, 0.741, 1213.328, 275.926, 0.433, 0.528, -11.371),
    (22249.289, 0.251, 693.416, 329.538, 0.337, 0.681, -13.487),
    # (fifteenth session: the corners' longer windows fit the second lens in 4 segments with
    # and without the refined rounds, 6 and 8 before; this one found by a seeded search)
    (7516.591, 0.952, 988.926, 553.922, 0.505, 0.604, 39.654),
    # (twentieth session: with the corners' free curve sides the first rounds fit the first
    # four lenses in as few segments as the refined rounds but one; these two found by a
    # seeded search, 7 against 8 and 3 against 5)
    (12343.354, 0.999, 736.851, 418.614, 0.508, 0.599, 10.002),
    (12407.138, 0.477, 741.747, 559.746, 0.464, 0.577, 28.923),
]


def test_the_refined_rounds_take_fewer_cubics_within_the_bound(monkeypatch):
    assert fewer_than_without(monkeypatch, "_REFINED_ROUNDS", False, LENSES) >= 3


def test_the_joint_rounds_never_share_a_segment_and_do_not_depend_on_the_index():
    j = np.array([3, 4, 5, 10, 11, 20])
    mv = np.array([0.2, 0.5, 0.3, 0.25, 0.4, 0.1])
    rounds = fitmod._joint_rounds(j, mv)
    seen = np.concatenate(rounds)
    assert sorted(seen.tolist()) == list(range(len(j)))  # every joint once
    for r in rounds:
        assert not np.any(np.diff(j[r]) == 1)  # no two in a round share a segment
    # the larger move of two neighbours goes first: (4 before 3 and 5, 11 before 10)
    first = set(j[rounds[0]].tolist())
    assert {4, 11, 20} <= first and not first & {3, 5, 10}
    # one segment fewer before them (every index after it one lower): the same order (an
    # even/odd split of the index flipped it)
    shifted = fitmod._joint_rounds(j - np.r_[0, 0, 0, 1, 1, 1], mv)
    assert [r.tolist() for r in shifted] == [r.tolist() for r in rounds]
