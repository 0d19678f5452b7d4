"""The ends of a long input gap kept as thinned points (``fit._gap_ends_kept``) never leave a
thinned segment beyond the line bound: where a gap lies *inside* a thinned segment, the point
kept at one of its ends splits the segment, and the part on the gap's other side holds the
gap and every point after it. That part is now measured too, and a kept point beside a part
that misses the bound is dropped. Before, it left a line 1.03 from its input points, over the
stated bound of 0.73 (a violation the fit promises never to make)."""

from __future__ import annotations

import numpy as np

from galvo_core import fit as fitmod
from galvo_core.thin import thin_many
from tests.test_fit_design_places import _fit_rounded, _scaled

#: Z003 Medium Italic (URW base35) "I"'s stroke (font units, laid out as in the benches' text),
#: to be set at em 2048: a long, nearly straight curve flattened into 12-unit chords, beside a
#: curve's dense end
_Z003_I = [
    ("cubic", (12422, 533), (12430, 534), (12437, 534), (12440, 534)),
    ("cubic", (12440, 534), (12454, 534), (12458, 534), (12486, 532)),
    ("cubic", (12486, 532), (12479, 502), (12474, 482), (12473, 475)),
    ("cubic", (12473, 475), (12456, 410), (12440, 346), (12424, 281)),
    ("line", (12424, 281), (12393, 155)),
    ("cubic", (12393, 155), (12391, 148), (12385, 125), (12376, 91)),
    ("cubic", (12376, 91), (12294, 47), (12251, 33), (12199, 33)),
    ("cubic", (12199, 33), (12142, 33), (12106, 78), (12106, 148)),
    ("cubic", (12106, 148), (12106, 260), (12177, 433), (12279, 570)),
    ("line", (12279, 570), (12273, 578)),
    ("cubic", (12273, 578), (12260, 574), (12259, 573), (12242, 566)),
    ("line", (12242, 566), (12232, 561)),
    ("cubic", (12232, 561), (12168, 572), (12164, 572), (12140, 572)),
    ("cubic", (12140, 572), (12092, 572), (12054, 560), (12020, 534)),
    ("cubic", (12020, 534), (11956, 484), (11916, 419), (11916, 363)),
    ("cubic", (11916, 363), (11916, 335), (11923, 310), (11945, 266)),
    ("line", (11945, 266), (12012, 320)),
    ("cubic", (12012, 320), (11986, 368), (11978, 393), (11978, 419)),
    ("cubic", (11978, 419), (11978, 474), (12027, 515), (12094, 515)),
    ("cubic", (12094, 515), (12123, 515), (12143, 511), (12187, 496)),
    ("cubic", (12187, 496), (12072, 315), (12024, 200), (12024, 109)),
    ("cubic", (12024, 109), (12024, 36), (12068, -13), (12134, -13)),
    ("cubic", (12134, -13), (12189, -13), (12253, 6), (12374, 58)),
    ("cubic", (12374, 58), (12367, 21), (12366, 17), (12366, 8)),
    ("cubic", (12366, 8), (12366, -6), (12375, -14), (12394, -14)),
    ("cubic", (12394, -14), (12422, -14), (12474, -6), (12546, 10)),
    ("line", (12546, 10), (12567, 35)),
    ("cubic", (12567, 35), (12536, 32), (12519, 31), (12495, 31)),
    ("cubic", (12495, 31), (12468, 31), (12458, 40), (12458, 65)),
    ("cubic", (12458, 65), (12458, 110), (12508, 323), (12578, 574)),
    ("cubic", (12578, 574), (12526, 566), (12519, 565), (12449, 558)),
    ("line", (12449, 558), (12422, 533)),
]


def test_kept_gap_ends_leave_no_segment_over_the_bound() -> None:
    """At the defaults the fit keeps every input point within the stated bound (``_fit_rounded``
    asserts zero violations), and every thinned segment after the gap ends are kept is a line
    within the line bound of its input points."""
    segs = _scaled(_Z003_I, 2.048)
    w, fp = _fit_rounded(segs)
    W = np.vstack([w, w[:1]]).astype(np.float64)
    eps = 0.02 + np.sqrt(0.5)
    K = np.asarray(thin_many([W], 0.02, per_path=np.array([eps]))[0], dtype=np.intp)
    tlen = np.array([len(K)])
    coarse = fitmod._coarse_chords(W, np.array([0]), np.array([len(W)]), np.array([1.0]))
    K2, tlen2 = fitmod._gap_ends_kept(W, K, tlen, np.array([1.0]), np.array([eps]), coarse)
    assert tlen2[0] == len(K2) and len(K2) >= len(K)
    err = fitmod._line_errors(W, np.stack([W[K2[:-1]], W[K2[1:]]], axis=1), K2[:-1], K2[1:])
    assert err.max() <= eps
