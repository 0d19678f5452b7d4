"""Rounded input, issue 16 (tenth session): a short line that the rounding left in a curve,
with its two neighbours, becomes one cubic (:meth:`_BatchFitter._bridge_round`).

On Cantarell Thin at em 2048 (whole units) the thinning leaves short lines inside smooth
design cubics ("8", the "%" ring); their thinned tangents are a few degrees off the design's,
so no cubic may end at them: the pair merges and the chain refit cannot get past them, but
one cubic over the line and both neighbours passes the same test."""

from __future__ import annotations

from galvo_core import fit as fitmod
from galvo_core import runs
from galvo_core.fit import check_fit, fit_paths
from tests._util import design_distance
from tests.test_fit_design_places import _dense, _rounded

#: Cantarell Thin at em 2048 in the precision bench's training text (bench/fonts.py): contour
#: 17, the "8"'s outer contour (8 design cubics), and 27, the "%"'s lower ring (4)
_EIGHT = [
    ('cubic',
     (11546.624, -20.48),
     (11812.864, -20.48),
     (11991.04, 116.736),
     (11991.04, 333.824)),
    ('cubic',
     (11991.04, 333.824),
     (11991.04, 575.488),
     (11769.856, 653.312),
     (11560.960000000001, 739.328)),
    ('cubic',
     (11560.960000000001, 739.328),
     (11778.048, 798.72),
     (11913.216, 935.936),
     (11913.216, 1112.064)),
    ('cubic',
     (11913.216, 1112.064),
     (11913.216, 1308.672),
     (11747.328, 1441.792),
     (11524.096, 1441.792)),
    ('cubic',
     (11524.096, 1441.792),
     (11298.816, 1441.792),
     (11155.456, 1308.672),
     (11155.456, 1101.824)),
    ('cubic',
     (11155.456, 1101.824),
     (11155.456, 905.216),
     (11296.768, 813.056),
     (11458.56, 743.424)),
    ('cubic',
     (11458.56, 743.424),
     (11243.52, 692.224),
     (11091.968, 532.48),
     (11091.968, 335.872)),
    ('cubic',
     (11091.968, 335.872),
     (11091.968, 122.88),
     (11274.24, -20.48),
     (11546.624, -20.48)),
]
_RING = [
    ('cubic',
     (16404.480000000003, -12.288),
     (16576.512000000002, -12.288),
     (16689.152000000002, 165.888),
     (16689.152000000002, 438.272)),
    ('cubic',
     (16689.152000000002, 438.272),
     (16689.152000000002, 708.6080000000001),
     (16578.56, 888.832),
     (16410.624000000003, 888.832)),
    ('cubic',
     (16410.624000000003, 888.832),
     (16236.544000000002, 888.832),
     (16123.904000000002, 708.6080000000001),
     (16123.904000000002, 432.128)),
    ('cubic',
     (16123.904000000002, 432.128),
     (16123.904000000002, 163.84),
     (16234.496000000001, -12.288),
     (16404.480000000003, -12.288)),
]


def test_a_short_line_in_a_curve_goes_into_one_cubic_with_its_neighbours(monkeypatch):
    # (the "8"'s short lines as the thinning leaves them without the jog rule of the
    # sixteenth session, runs._CLUSTER_JOG: with it, the clusters there are smooth and the
    # "8" is fitted in 13 segments with or without the bridge, 10 before, at the same
    # distance to the design)
    monkeypatch.setattr(runs, "_CLUSTER_JOG", False)
    designs = [_EIGHT, _RING]
    pts = [_rounded(d) for d in designs]
    truth = [_dense(d, 0.001) for d in designs]

    def fit():
        fps = fit_paths(pts, [True] * len(pts))
        for f, p in zip(fps, pts, strict=True):
            assert not check_fit(p, f, 0.02, 0.02, report=True)["violation"]
        d = [design_distance(f, t) for f, t in zip(fps, truth, strict=True)]
        return [f.n_segments for f in fps], d

    n, d = fit()
    monkeypatch.setattr(fitmod, "_BRIDGE_ROUNDS", 0)
    n0, d0 = fit()
    assert n[0] < n0[0] and n[1] <= n0[1], (n, n0)
    assert n[1] <= len(_RING) + 1  # the ring: its four design cubics, or one more
    assert d[1] < 0.6, d  # the distance to the true curve
    assert d[0] <= d0[0] + 0.02, (d, d0)
