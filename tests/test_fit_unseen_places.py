"""Rounded input, issue 16 (sixteenth session): places of unseen typefaces (URW Z003
Medium Italic, P052 Bold Italic and Bookman Light Italic at em 2048, not on a fresh machine:
inline contours as bench/fonts.py reads them, coordinates to 0.01) where the fit lay
0.69-0.97 from the design:

- a corner whose line side is a chain of design lines each written as its two rounded ends
  (``fit._FIRST_CHAIN``: the side's first step gives the corner its direction);
- a jog of the rounding (a cluster of short thinned segments) between two parallel diagonal
  segments inside a curve (``runs._CLUSTER_JOG``: smooth, not two corners);
- a cubic that swallowed a design line written as its two rounded ends, the line being its
  end segment alone (``fit._LONE_BULGE_GAP``: a line there at a smaller bulge);
- a smooth vertex beside a thinned segment that is mostly one long input step (a design line
  written as its two rounded ends) moving across that line (``fit._SMOOTH_ALONG_SHARE``);
- (seventeenth session) a curve's first few dense steps taken into the design line before it
  (``fit._GAP_SHORT_REST``: the line's end input point kept);
- (seventeenth session, FreeMono Bold at em 1000) a cluster of short thinned segments made
  smooth on its net turn although one of its vertices is a corner (``runs._CLUSTER_TURNS``);
- (eighteenth session) a line piece of the curve-run rules that the fitter's merge rounds took
  into a cubic between two curves (``fit._LONE_MIDDLE``: a line again);
- (nineteenth session) a row of collinear input points with no long gap, a cubic's end
  segment (``fit._LONE_ROW``: a line again);
- (nineteenth session) a unit jog of the rounding between a long design line and the first
  chord of the curve it flows into (``runs._CLUSTER_UNIT``: smooth, not two corners);
- (nineteenth session) a corner kept three input points past the design's, where its own
  estimate lies in the design corner's rounding square (``fit._MISPLACED_EST``)."""

from __future__ import annotations

import numpy as np
import pytest

from galvo_core import fit as fitmod
from galvo_core import runs
from galvo_core.geometry import point_polyline_distance
from tests._util import flattened_cubic, resampled
from tests.test_fit_design_places import _dense, _fit_rounded, _scaled


def _near(segs, fp, place, r: float = 2.0) -> float:
    """Both-ways distance of the fit and the design within ``r`` of ``place``."""
    truth = resampled(_dense(segs, 0.001), 0.25)
    fit = resampled(np.vstack([flattened_cubic(*s.points, chord=0.002) if s.kind == "cubic"
                               else np.asarray(s.points) for s in fp.segments]), 0.25)
    out = 0.0
    for a, b in ((truth, fit), (fit, truth)):
        near = a[np.hypot(*(a - place).T) <= r]
        assert len(near)
        out = max(out, float(point_polyline_distance(near, b).max()))
    return out

#: Z003 Medium Italic "4", contour 76: at (57321.47, 317.44) a cubic meets the first of three
#: design lines (80, 141 and 150 units, turning 0.6 degrees between them), each written as its
#: two rounded ends; the thinning made them one line, whose least-squares line lies 0.8 below
#: the first one at the corner
_FOUR = [
    ('cubic', (57677.82, -28.67), (57696.26, -43.01), (57700.35, -47.10), (57720.83, -51.20)),
    ('cubic', (57720.83, -51.20), (57778.18, -26.62), (57845.76, -2.05), (57890.82, 10.24)),
    ('line', (57890.82, 10.24), (57894.91, 26.62)),
    ('cubic', (57894.91, 26.62), (57876.48, 55.30), (57872.38, 71.68), (57872.38, 100.35)),
    ('cubic', (57872.38, 100.35), (57872.38, 143.36), (57880.58, 198.66), (57907.20, 311.30)),
    ('line', (57907.20, 311.30), (57944.06, 311.30)),
    ('line', (57944.06, 311.30), (57993.22, 311.30)),
    ('line', (57993.22, 311.30), (58025.98, 311.30)),
    ('line', (58025.98, 311.30), (58101.76, 417.79)),
    ('cubic', (58101.76, 417.79), (58066.94, 415.74), (58040.32, 415.74), (58025.98, 415.74)),
    ('cubic', (58025.98, 415.74), (58003.46, 415.74), (57980.93, 415.74), (57931.78, 417.79)),
    ('line', (57931.78, 417.79), (57962.50, 546.82)),
    ('line', (57962.50, 546.82), (58062.85, 1007.62)),
    ('cubic', (58062.85, 1007.62), (58085.38, 1097.73), (58091.52, 1122.30), (58112.00, 1198.08)),
    ('cubic', (58112.00, 1198.08), (58097.66, 1191.94), (58085.38, 1187.84), (58079.23, 1185.79)),
    ('line', (58079.23, 1185.79), (58046.46, 1167.36)),
    ('cubic', (58046.46, 1167.36), (58030.08, 1161.22), (58015.74, 1153.02), (57999.36, 1144.83)),
    ('line', (57999.36, 1144.83), (57968.64, 1128.45)),
    ('cubic', (57968.64, 1128.45), (57960.45, 1116.16), (57923.58, 1075.20), (57919.49, 1071.10)),
    ('cubic', (57919.49, 1071.10), (57853.95, 997.38), (57788.42, 923.65), (57724.93, 851.97)),
    ('cubic', (57724.93, 851.97), (57643.01, 755.71), (57608.19, 712.70), (57393.15, 444.42)),
    ('cubic', (57393.15, 444.42), (57366.53, 411.65), (57352.19, 385.02), (57321.47, 317.44)),
    ('line', (57321.47, 317.44), (57401.34, 315.39)),
    ('line', (57401.34, 315.39), (57542.66, 313.34)),
    ('line', (57542.66, 313.34), (57692.16, 311.30)),
    ('line', (57692.16, 311.30), (57763.84, 311.30)),
    ('line', (57763.84, 311.30), (57677.82, -28.67)),
]

#: P052 Bold Italic "Q", contour 23: the tail's one cubic, rounded as steps (-2, 1), (-3, 1) x 3,
#: then a (-2, 2) jog and a cluster of short segments; the thinning kept corners around it
_Q = [
    ('line', (22695.94, -348.16), (22706.18, -344.06)),
    ('cubic', (22706.18, -344.06), (22708.22, -221.18), (22769.66, -143.36), (22865.92, -143.36)),
    ('cubic', (22865.92, -143.36), (22915.07, -143.36), (22966.27, -157.70), (23013.38, -182.27)),
    ('line', (23013.38, -182.27), (23420.93, -401.41)),
    ('cubic', (23420.93, -401.41), (23498.75, -444.42), (23533.57, -454.66), (23588.86, -454.66)),
    ('cubic', (23588.86, -454.66), (23752.70, -454.66), (23867.39, -331.78), (23914.50, -108.54)),
    ('line', (23914.50, -108.54), (23851.01, -88.06)),
    ('cubic', (23851.01, -88.06), (23826.43, -215.04), (23773.18, -272.38), (23685.12, -272.38)),
    ('cubic', (23685.12, -272.38), (23625.73, -272.38), (23515.14, -239.62), (23392.26, -186.37)),
    ('line', (23392.26, -186.37), (23199.74, -102.40)),
    ('cubic', (23199.74, -102.40), (23085.06, -53.25), (22984.70, -24.58), (22915.07, -24.58)),
    ('cubic', (22915.07, -24.58), (22747.14, -24.58), (22648.83, -131.07), (22646.78, -315.39)),
    ('line', (22646.78, -315.39), (22695.94, -348.16)),
]

#: P052 Bold Italic "r", contour 61: a 149-unit design line from the tip at (54847.49, 448.51),
#: written as its two rounded ends; the cubic after the tip took it in, 0.298 quanta off its chord
_R = [
    ('line', (54505.47, 720.90), (54532.10, 667.65)),
    ('line', (54532.10, 667.65), (54601.73, 716.80)),
    ('cubic', (54601.73, 716.80), (54638.59, 743.42), (54669.31, 757.76), (54687.74, 757.76)),
    ('cubic', (54687.74, 757.76), (54704.13, 757.76), (54712.32, 745.47), (54712.32, 724.99)),
    ('cubic', (54712.32, 724.99), (54712.32, 669.70), (54712.32, 669.70), (54659.07, 397.31)),
    ('line', (54659.07, 397.31), (54609.92, 178.18)),
    ('cubic', (54609.92, 178.18), (54597.63, 126.98), (54583.30, 77.82), (54554.62, -10.24)),
    ('line', (54554.62, -10.24), (54577.15, -34.82)),
    ('cubic', (54577.15, -34.82), (54632.45, -16.38), (54679.55, -8.19), (54798.34, 4.10)),
    ('cubic', (54798.34, 4.10), (54827.01, 190.46), (54849.54, 292.86), (54882.30, 385.02)),
    ('cubic', (54882.30, 385.02), (54960.13, 598.02), (55040.00, 694.27), (55134.21, 694.27)),
    ('cubic', (55134.21, 694.27), (55169.02, 694.27), (55195.65, 684.03), (55240.70, 655.36)),
    ('line', (55240.70, 655.36), (55265.28, 667.65)),
    ('cubic', (55265.28, 667.65), (55265.28, 753.66), (55275.52, 813.06), (55306.24, 948.22)),
    ('cubic', (55306.24, 948.22), (55285.76, 958.46), (55271.42, 960.51), (55250.94, 960.51)),
    ('cubic', (55250.94, 960.51), (55193.60, 960.51), (55142.40, 935.94), (55093.25, 884.74)),
    ('cubic', (55093.25, 884.74), (55037.95, 827.39), (55005.18, 770.05), (54847.49, 448.51)),
    ('line', (54847.49, 448.51), (54880.26, 593.92)),
    ('cubic', (54880.26, 593.92), (54896.64, 663.55), (54904.83, 694.27), (54913.02, 735.23)),
    ('cubic', (54913.02, 735.23), (54935.55, 821.25), (54943.74, 864.26), (54943.74, 894.98)),
    ('cubic', (54943.74, 894.98), (54943.74, 937.98), (54925.31, 960.51), (54892.54, 960.51)),
    ('cubic', (54892.54, 960.51), (54837.25, 960.51), (54763.52, 923.65), (54671.36, 851.97)),
    ('line', (54671.36, 851.97), (54505.47, 720.90)),
]


#: URW Bookman Light Italic "m" at em 2048, contour 54: at (49055.74, 995.33) a 78-unit design
#: line (the serif's top, written as its two rounded ends) meets a cubic at 13 degrees; the
#: thinning ends the line 4 units into the curve, at a smooth vertex
_BM = [
    ('line', (48764.93, 0.00), (48953.34, 0.00)),
    ('line', (48953.34, 0.00), (49096.70, 792.58)),
    ('cubic', (49096.70, 792.58), (49195.01, 868.35), (49315.84, 917.50), (49399.81, 917.50)),
    ('cubic', (49399.81, 917.50), (49489.92, 917.50), (49539.07, 872.45), (49539.07, 792.58)),
    ('cubic', (49539.07, 792.58), (49539.07, 763.90), (49534.98, 735.23), (49522.69, 663.55)),
    ('line', (49522.69, 663.55), (49401.86, 0.00)),
    ('line', (49401.86, 0.00), (49590.27, 0.00)),
    ('line', (49590.27, 0.00), (49733.63, 792.58)),
    ('cubic', (49733.63, 792.58), (49838.08, 870.40), (49948.67, 917.50), (50030.59, 917.50)),
    ('cubic', (50030.59, 917.50), (50120.70, 917.50), (50176.00, 868.35), (50176.00, 788.48)),
    ('cubic', (50176.00, 788.48), (50176.00, 761.86), (50173.95, 745.47), (50163.71, 690.18)),
    ('line', (50163.71, 690.18), (50092.03, 299.01)),
    ('cubic', (50092.03, 299.01), (50085.89, 262.14), (50079.74, 204.80), (50079.74, 184.32)),
    ('cubic', (50079.74, 184.32), (50079.74, 65.54), (50157.57, -18.43), (50268.16, -18.43)),
    ('cubic', (50268.16, -18.43), (50360.32, -18.43), (50454.53, 22.53), (50528.26, 98.30)),
    ('line', (50528.26, 98.30), (50491.39, 149.50)),
    ('cubic', (50491.39, 149.50), (50442.24, 104.45), (50409.47, 88.06), (50370.56, 88.06)),
    ('cubic', (50370.56, 88.06), (50309.12, 88.06), (50270.21, 129.02), (50270.21, 194.56)),
    ('cubic', (50270.21, 194.56), (50270.21, 221.18), (50276.35, 272.38), (50286.59, 331.78)),
    ('line', (50286.59, 331.78), (50356.22, 706.56)),
    ('cubic', (50356.22, 706.56), (50364.42, 759.81), (50368.51, 790.53), (50368.51, 817.15)),
    ('cubic', (50368.51, 817.15), (50368.51, 940.03), (50272.26, 1013.76), (50112.51, 1013.76)),
    ('cubic', (50112.51, 1013.76), (49979.39, 1013.76), (49860.61, 968.70), (49727.49, 866.30)),
    ('cubic', (49727.49, 866.30), (49694.72, 964.61), (49612.80, 1013.76), (49477.63, 1013.76)),
    ('cubic', (49477.63, 1013.76), (49360.90, 1013.76), (49258.50, 976.90), (49115.14, 886.78)),
    ('line', (49115.14, 886.78), (49133.57, 995.33)),
    ('line', (49133.57, 995.33), (49055.74, 995.33)),
    ('cubic', (49055.74, 995.33), (48939.01, 968.70), (48908.29, 962.56), (48769.02, 950.27)),
    ('line', (48769.02, 950.27), (48758.78, 890.88)),
    ('line', (48758.78, 890.88), (48783.36, 886.78)),
    ('cubic', (48783.36, 886.78), (48871.42, 872.45), (48902.14, 843.78), (48902.14, 784.38)),
    ('cubic', (48902.14, 784.38), (48902.14, 763.90), (48900.10, 751.62), (48898.05, 733.18)),
    ('line', (48898.05, 733.18), (48764.93, 0.00)),
]


#: Z003 Medium Italic "3" at em 2048, contour 75: a 59-unit design line (written as its two
#: rounded ends) meets a cubic at 15 degrees at (57139.20, 847.87); the thinning took the
#: curve's first two steps into the line, which then ended 3.6 units into the curve
_THREE = [
    ('cubic', (56352.77, 53.25), (56438.78, 6.14), (56504.32, -12.29), (56594.43, -12.29)),
    ('cubic', (56594.43, -12.29), (56885.25, -12.29), (57188.35, 266.24), (57188.35, 532.48)),
    ('cubic', (57188.35, 532.48), (57188.35, 595.97), (57159.68, 653.31), (57112.58, 686.08)),
    ('cubic', (57112.58, 686.08), (57079.81, 708.61), (57051.14, 718.85), (56979.46, 729.09)),
    ('cubic', (56979.46, 729.09), (56997.89, 741.38), (57012.22, 751.62), (57028.61, 765.95)),
    ('line', (57028.61, 765.95), (57092.10, 813.06)),
    ('line', (57092.10, 813.06), (57139.20, 847.87)),
    ('cubic', (57139.20, 847.87), (57192.45, 915.46), (57214.98, 966.66), (57214.98, 1030.14)),
    ('cubic', (57214.98, 1030.14), (57214.98, 1118.21), (57145.34, 1177.60), (57042.94, 1177.60)),
    ('cubic', (57042.94, 1177.60), (57014.27, 1177.60), (56989.70, 1173.50), (56938.50, 1159.17)),
    ('cubic', (56938.50, 1159.17), (56911.87, 1144.83), (56889.34, 1132.54), (56881.15, 1126.40)),
    ('cubic', (56881.15, 1126.40), (56868.86, 1120.26), (56840.19, 1097.73), (56795.14, 1067.01)),
    ('cubic', (56795.14, 1067.01), (56786.94, 1060.86), (56766.46, 1046.53), (56735.74, 1026.05)),
    ('line', (56735.74, 1026.05), (56733.70, 974.85)),
    ('cubic', (56733.70, 974.85), (56817.66, 1028.10), (56895.49, 1060.86), (56942.59, 1060.86)),
    ('cubic', (56942.59, 1060.86), (57010.18, 1060.86), (57057.28, 1009.66), (57057.28, 940.03)),
    ('cubic', (57057.28, 940.03), (57057.28, 815.10), (56936.45, 716.80), (56653.82, 608.26)),
    ('line', (56653.82, 608.26), (56647.68, 555.01)),
    ('cubic', (56647.68, 555.01), (56815.62, 618.50), (56815.62, 618.50), (56858.62, 618.50)),
    ('cubic', (56858.62, 618.50), (56958.98, 618.50), (57030.66, 538.62), (57030.66, 421.89)),
    ('cubic', (57030.66, 421.89), (57030.66, 337.92), (56995.84, 247.81), (56938.50, 180.22)),
    ('cubic', (56938.50, 180.22), (56881.15, 112.64), (56803.33, 77.82), (56713.22, 77.82)),
    ('cubic', (56713.22, 77.82), (56635.39, 77.82), (56598.53, 88.06), (56446.98, 157.70)),
    ('line', (56446.98, 157.70), (56352.77, 53.25)),
]

#: FreeMono Bold "c" at em 1000 (the font's own units: its corners are on input points),
#: contour 38: a 95-degree cusp at (17254, 420) between a 26-unit thinned segment and four
#: of 9-12 units turning 12-19 degrees the other way; the cluster rule saw only their net turn
_C = [
    ('line', (17340.00, 307.00), (17340.00, 384.00)),
    ('cubic', (17340.00, 384.00), (17340.00, 430.00), (17325.00, 450.00), (17292.00, 450.00)),
    ('cubic', (17292.00, 450.00), (17271.00, 450.00), (17260.00, 441.00), (17254.00, 420.00)),
    ('cubic', (17254.00, 420.00), (17215.00, 440.00), (17167.00, 450.00), (17110.00, 450.00)),
    ('cubic', (17110.00, 450.00), (16959.00, 450.00), (16854.00, 350.00), (16854.00, 207.00)),
    ('cubic', (16854.00, 207.00), (16854.00, 110.00), (16908.00, -16.00), (17123.00, -16.00)),
    ('cubic', (17123.00, -16.00), (17273.00, -16.00), (17365.00, 34.00), (17365.00, 89.00)),
    ('cubic', (17365.00, 89.00), (17365.00, 117.00), (17342.00, 140.00), (17315.00, 140.00)),
    ('cubic', (17315.00, 140.00), (17274.00, 140.00), (17284.00, 84.00), (17130.00, 84.00)),
    ('cubic', (17130.00, 84.00), (17013.00, 84.00), (16954.00, 125.00), (16954.00, 207.00)),
    ('cubic', (16954.00, 207.00), (16954.00, 292.00), (17015.00, 350.00), (17110.00, 350.00)),
    ('cubic', (17110.00, 350.00), (17154.00, 350.00), (17190.00, 341.00), (17216.00, 325.00)),
    ('cubic', (17216.00, 325.00), (17252.00, 299.00), (17228.00, 241.00), (17290.00, 241.00)),
    ('cubic', (17290.00, 241.00), (17332.00, 241.00), (17340.00, 272.00), (17340.00, 307.00)),
]

#: FreeMono Bold "@" at em 1000, contour 86: a curve, a 3-unit design line down and a line
#: on, two corners of 90-98 degrees whose net turn is nothing
_AT = [
    ('cubic', (37502.00, -152.00), (37597.00, -152.00), (37679.00, -113.00), (37679.00, -66.00)),
    ('cubic', (37679.00, -66.00), (37679.00, -43.00), (37661.00, -25.00), (37639.00, -25.00)),
    ('cubic', (37639.00, -25.00), (37608.00, -25.00), (37606.00, -74.00), (37505.00, -74.00)),
    ('cubic', (37505.00, -74.00), (37385.00, -74.00), (37355.00, 70.00), (37355.00, 161.00)),
    ('line', (37355.00, 161.00), (37355.00, 317.00)),
    ('cubic', (37355.00, 317.00), (37355.00, 445.00), (37418.00, 541.00), (37502.00, 541.00)),
    ('cubic', (37502.00, 541.00), (37564.00, 541.00), (37607.00, 495.00), (37607.00, 429.00)),
    ('line', (37607.00, 429.00), (37607.00, 397.00)),
    ('cubic', (37607.00, 397.00), (37495.00, 389.00), (37418.00, 319.00), (37418.00, 226.00)),
    ('cubic', (37418.00, 226.00), (37418.00, 143.00), (37489.00, 72.00), (37574.00, 72.00)),
    ('cubic', (37574.00, 72.00), (37583.00, 72.00), (37592.00, 73.00), (37607.00, 75.00)),
    ('line', (37607.00, 75.00), (37607.00, 72.00)),
    ('line', (37607.00, 72.00), (37654.00, 72.00)),
    ('cubic', (37654.00, 72.00), (37691.00, 72.00), (37709.00, 85.00), (37709.00, 113.00)),
    ('cubic', (37709.00, 113.00), (37709.00, 130.00), (37702.00, 141.00), (37686.00, 148.00)),
    ('line', (37686.00, 148.00), (37686.00, 429.00)),
    ('cubic', (37686.00, 429.00), (37686.00, 540.00), (37609.00, 620.00), (37501.00, 620.00)),
    ('cubic', (37501.00, 620.00), (37371.00, 620.00), (37276.00, 495.00), (37276.00, 323.00)),
    ('line', (37276.00, 323.00), (37276.00, 154.00)),
    ('cubic', (37276.00, 154.00), (37276.00, 39.00), (37321.00, -152.00), (37502.00, -152.00)),
]


#: Z003 Medium Italic "l" at em 1000 (= font units), contour 53, its foot: a
#: 9-unit design line (two) after a curve's tangent end, written with the curve's last dense
#: points as a 16-unit row of ten collinear points (steps up to 6 units, no long gap), then a
#: 27-degree corner; one cubic over the row and the curve after it bowed 0.70 below the row,
#: where the rounded input is on the design
_L1000 = [
    ('cubic', (20127, 129), (20106, 117), (20106, 117), (20063, 90)),
    ('cubic', (20063, 90), (20034, 72), (20017, 64), (20006, 64)),
    ('cubic', (20006, 64), (19996, 64), (19988, 76), (19988, 90)),
    ('line', (19988, 90), (19988, 99)),
    ('line', (19988, 99), (19988, 108)),
    ('cubic', (19988, 108), (19988, 126), (20033, 320), (20070, 461)),
    ('cubic', (20070, 461), (20109, 609), (20118, 626), (20162, 626)),
    ('cubic', (20162, 626), (20177, 626), (20187, 625), (20211, 619)),
    ('line', (20211, 619), (20254, 672)),
    ('cubic', (20254, 672), (20233, 677), (20223, 678), (20209, 678)),
    ('cubic', (20209, 678), (20169, 678), (20138, 663), (20089, 619)),
    ('cubic', (20089, 619), (20045, 580), (20034, 564), (20021, 528)),
    ('cubic', (20021, 528), (20013, 504), (19991, 423), (19981, 379)),
    ('line', (19981, 379), (19909, 66)),
    ('cubic', (19909, 66), (19908, 60), (19907, 54), (19907, 48)),
    ('cubic', (19907, 48), (19907, 17), (19924, -13), (19940, -13)),
    ('line', (19940, -13), (19946, -13)),
    ('line', (19946, -13), (19949, -13)),
    ('cubic', (19949, -13), (19955, -16), (19987, 6), (20127, 107)),
    ('line', (20127, 107), (20127, 129)),
]


#: Z003 Medium Italic "l" at em 2048 (``_L1000`` times 2.048): a 37-unit vertical design line
#: written as three rounded points between two dense curves; the curve-run rules kept it a line
#: piece, and the fitter's merge rounds took it and both curves into one cubic bowing 0.33 off
#: the points' column, away from the design (0.76 from it where the rounded input is 0.42)
_L = _scaled(_L1000, 2.048)


#: Z003 Medium Italic "f" at em 2048 (here in font units, times 2.048), contour 43, its
#: crossbar: a 100-unit design line sloping 2 degrees flows into a flat curve; where the line's
#: rounded row steps up one unit (a unit jog), the jog between the long line and the curve's
#: first 24-unit chord was kept as two corners (the two longer segments' lengths not within
#: the curve-run ratio), each moved 0.4 off its input point: 0.90 from the design where the
#: rounded input is 0.50
_F = _scaled([
    ('cubic', (17686, -208), (17678, -219), (17669, -230), (17661, -242)),
    ('cubic', (17661, -242), (17683, -245), (17692, -246), (17710, -246)),
    ('cubic', (17710, -246), (17743, -246), (17769, -241), (17785, -232)),
    ('cubic', (17785, -232), (17814, -216), (17865, -167), (17892, -132)),
    ('cubic', (17892, -132), (17923, -90), (17959, -5), (17982, 87)),
    ('cubic', (17982, 87), (18020, 230), (18039, 304), (18041, 311)),
    ('cubic', (18041, 311), (18050, 310), (18054, 310), (18058, 310)),
    ('line', (18058, 310), (18110, 312)),
    ('cubic', (18110, 312), (18113, 312), (18119, 312), (18129, 311)),
    ('line', (18129, 311), (18171, 343)),
    ('cubic', (18171, 343), (18142, 344), (18131, 344), (18107, 344)),
    ('cubic', (18107, 344), (18085, 344), (18076, 344), (18049, 343)),
    ('cubic', (18049, 343), (18114, 598), (18128, 628), (18188, 628)),
    ('cubic', (18188, 628), (18206, 628), (18220, 626), (18255, 620)),
    ('line', (18255, 620), (18301, 674)),
    ('cubic', (18301, 674), (18281, 679), (18273, 680), (18253, 680)),
    ('cubic', (18253, 680), (18192, 680), (18152, 659), (18084, 593)),
    ('cubic', (18084, 593), (18028, 538), (18015, 510), (17976, 343)),
    ('cubic', (17976, 343), (17966, 344), (17961, 344), (17956, 344)),
    ('line', (17956, 344), (17907, 342)),
    ('cubic', (17907, 342), (17905, 342), (17900, 342), (17892, 343)),
    ('cubic', (17892, 343), (17886, 339), (17880, 335), (17878, 334)),
    ('cubic', (17878, 334), (17867, 328), (17865, 326), (17856, 322)),
    ('cubic', (17856, 322), (17853, 320), (17845, 316), (17836, 311)),
    ('line', (17836, 311), (17861, 311)),
    ('line', (17861, 311), (17931, 310)),
    ('cubic', (17931, 310), (17937, 310), (17948, 310), (17968, 311)),
    ('cubic', (17968, 311), (17952, 250), (17946, 224), (17927, 136)),
    ('cubic', (17927, 136), (17867, -140), (17844, -184), (17759, -184)),
    ('cubic', (17759, -184), (17744, -184), (17732, -183), (17706, -179)),
    ('line', (17706, -179), (17686, -208)),
], 2.048)

#: Z003 Medium Italic "b" at em 2048 (here in font units, times 2.048), contour 34: a
#: 19-degree corner between two curves that the thinning kept three input points late; the
#: sides fitted again without the points beside it cross past the kept point, while the
#: corner's own estimate lies by the design's: 0.78 from the design where the rounded input is
#: 0.54
_B = _scaled([
    ('cubic', (16292, 131), (16219, 81), (16202, 71), (16192, 71)),
    ('cubic', (16192, 71), (16185, 71), (16180, 79), (16180, 91)),
    ('cubic', (16180, 91), (16180, 118), (16203, 223), (16240, 360)),
    ('cubic', (16240, 360), (16251, 376), (16253, 378), (16269, 396)),
    ('cubic', (16269, 396), (16221, 407), (16187, 411), (16143, 411)),
    ('cubic', (16143, 411), (16102, 411), (16082, 407), (16057, 391)),
    ('cubic', (16057, 391), (16021, 370), (15979, 339), (15966, 325)),
    ('cubic', (15966, 325), (15928, 283), (15887, 148), (15887, 67)),
    ('cubic', (15887, 67), (15887, 19), (15903, -13), (15928, -13)),
    ('cubic', (15928, -13), (15950, -13), (15983, 7), (16108, 97)),
    ('cubic', (16108, 97), (16097, 46), (16093, 21), (16093, 8)),
    ('cubic', (16093, 8), (16093, -6), (16099, -13), (16109, -13)),
    ('cubic', (16109, -13), (16122, -13), (16130, -9), (16201, 38)),
    ('cubic', (16201, 38), (16235, 61), (16254, 74), (16291, 101)),
    ('line', (16291, 101), (16292, 131)),
], 2.048)

@pytest.mark.parametrize(("segs", "place", "mod", "knob", "off", "now", "before"), [
    (_FOUR, (57321.47, 317.44), fitmod, "_FIRST_CHAIN", False, 0.6, 0.9),
    (_Q, (23187.4, -98.1), runs, "_CLUSTER_JOG", False, 0.3, 0.75),
    (_R, (54857.2, 494.9), fitmod, "_LONE_BULGE_GAP", fitmod._LONE_BULGE, 0.35, 0.7),
    # (the vertex moved onto the curve's estimate tilted the line off its row: 0.69 from
    # the design corner where the rounded input is 0.33)
    (_BM, (49055.7, 995.3), fitmod, "_SMOOTH_ALONG_SHARE", 0.0, 0.45, 0.6),
    # (the line's end 0.80 from the design corner where the rounded input is 0.23)
    (_THREE, (57139.2, 847.9), fitmod, "_GAP_SHORT_REST", 10**9, 0.45, 0.7),
    # (each corner moved off its input point, the design's, to a corner of its rounding
    # square: 0.68 and 0.71 from the design where the rounded input is 0.28 and 0.26)
    (_C, (17254.0, 420.0), runs, "_CLUSTER_TURNS", False, 0.3, 0.6),
    (_AT, (37607.0, 75.0), runs, "_CLUSTER_TURNS", False, 0.35, 0.6),
    # (eighteenth session: the line made a line again, both curves re-fitted apart)
    (_L, (40934.7, 200.4), fitmod, "_LONE_MIDDLE", False, 0.5, 0.7),
    (_L, (40850.7, -27.4), fitmod, "_LONE_MIDDLE", False, 0.5, 0.7),
    # (nineteenth session: the row made a line, the curve after it re-fitted alone)
    (_L1000, (19946.4, -13.7), fitmod, "_LONE_ROW", False, 0.4, 0.65),
    # (nineteenth session: the jog's vertices smooth, the line and the curve one run)
    (_F, (36667.5, 699.6), runs, "_CLUSTER_UNIT", 0.0, 0.55, 0.8),
    # (nineteenth session: the corner kept on the input point by its estimate)
    (_B, (33259.5, 737.3), fitmod, "_MISPLACED_EST", False, 0.45, 0.7),
], ids=["line-chain-corner", "diagonal-jog-cluster", "swallowed-gap-line",
        "smooth-vertex-along-a-long-step", "curve-steps-after-a-gap-line",
        "cusp-in-a-cluster", "step-in-a-cluster", "line-piece-inside-a-cubic",
        "line-piece-inside-a-cubic-row", "collinear-row-at-a-cubic-end",
        "unit-jog-after-a-long-line", "corner-kept-late-by-its-estimate"])
def test_the_fit_lies_near_the_design_there(segs, place, mod, knob, off, now, before,
                                            monkeypatch):
    p = np.array(place)
    d = _near(segs, _fit_rounded(segs)[1], p)
    monkeypatch.setattr(mod, knob, off)
    d0 = _near(segs, _fit_rounded(segs)[1], p)
    assert d < now and d0 > before, (d, d0)


#: URW C059 Roman "M" at em 2048, contour 16: long vertical stems (rounded columns) with
#: clusters of short segments between parallel axis-parallel runs; taken for jogs
#: (``runs._CLUSTER_DIAG`` 0), the stems went into cubics that sagged 0.86 from the design
_M = [
    ('line', (17692.67, 1478.66), (17164.29, 1478.66)),
    ('line', (17164.29, 1478.66), (17164.29, 1382.40)),
    ('line', (17164.29, 1382.40), (17203.20, 1382.40)),
    ('cubic', (17203.20, 1382.40), (17319.94, 1380.35), (17358.85, 1374.21), (17373.18, 1353.73)),
    ('cubic', (17373.18, 1353.73), (17387.52, 1335.30), (17387.52, 1333.25), (17387.52, 1226.75)),
    ('line', (17387.52, 1226.75), (17387.52, 442.37)),
    ('cubic', (17387.52, 442.37), (17387.52, 163.84), (17348.61, 106.50), (17149.95, 96.26)),
    ('line', (17149.95, 96.26), (17149.95, 0.00)),
    ('line', (17149.95, 0.00), (17733.63, 0.00)),
    ('line', (17733.63, 0.00), (17733.63, 96.26)),
    ('cubic', (17733.63, 96.26), (17537.02, 106.50), (17498.11, 163.84), (17498.11, 442.37)),
    ('line', (17498.11, 442.37), (17498.11, 1347.58)),
    ('line', (17498.11, 1347.58), (17985.54, 0.00)),
    ('line', (17985.54, 0.00), (18067.46, 0.00)),
    ('line', (18067.46, 0.00), (18524.16, 1347.58)),
    ('line', (18524.16, 1347.58), (18524.16, 251.90)),
    ('cubic', (18524.16, 251.90), (18524.16, 147.46), (18524.16, 143.36), (18511.87, 122.88)),
    ('cubic', (18511.87, 122.88), (18495.49, 102.40), (18456.58, 96.26), (18339.84, 96.26)),
    ('line', (18339.84, 96.26), (18302.98, 96.26)),
    ('line', (18302.98, 96.26), (18302.98, 0.00)),
    ('line', (18302.98, 0.00), (18974.72, 0.00)),
    ('line', (18974.72, 0.00), (18974.72, 96.26)),
    ('line', (18974.72, 96.26), (18937.86, 96.26)),
    ('cubic', (18937.86, 96.26), (18821.12, 96.26), (18782.21, 102.40), (18765.82, 122.88)),
    ('cubic', (18765.82, 122.88), (18753.54, 143.36), (18753.54, 145.41), (18753.54, 251.90)),
    ('line', (18753.54, 251.90), (18753.54, 1226.75)),
    ('cubic', (18753.54, 1226.75), (18753.54, 1331.20), (18753.54, 1335.30), (18765.82, 1353.73)),
    ('cubic', (18765.82, 1353.73), (18782.21, 1374.21), (18821.12, 1380.35), (18937.86, 1382.40)),
    ('line', (18937.86, 1382.40), (18974.72, 1382.40)),
    ('line', (18974.72, 1382.40), (18974.72, 1478.66)),
    ('line', (18974.72, 1478.66), (18460.67, 1478.66)),
    ('line', (18460.67, 1478.66), (18085.89, 387.07)),
    ('line', (18085.89, 387.07), (17692.67, 1478.66)),
]

#: DejaVu Serif Bold Italic "Q" at em 400 (the training text), contour 7: a 30-unit design line
#: (1054.10, -78.52)-(1024.02, -78.52) written as its two rounded ends, then the curve's start
#: (the font's quadratics as the cubics they are)
_SBQ = [
    ('cubic', (924.41, -5.66), (880.14, -4.88), (848.05, 8.79), (828.12, 35.35)),
    ('cubic', (828.12, 35.35), (813.93, 54.23), (806.84, 78.19), (806.84, 107.23)),
    ('cubic', (806.84, 107.23), (806.84, 119.08), (808.01, 131.84), (810.35, 145.51)),
    ('cubic', (810.35, 145.51), (818.56, 192.64), (837.60, 229.65), (867.48, 256.54)),
    ('cubic', (867.48, 256.54), (897.36, 283.43), (934.31, 296.88), (978.32, 296.88)),
    ('cubic', (978.32, 296.88), (1022.46, 296.88), (1054.75, 283.47), (1075.20, 256.64)),
    ('cubic', (1075.20, 256.64), (1089.65, 237.50), (1096.88, 213.22), (1096.88, 183.79)),
    ('cubic', (1096.88, 183.79), (1096.88, 171.94), (1095.71, 159.18), (1093.36, 145.51)),
    ('cubic', (1093.36, 145.51), (1086.07, 104.10), (1070.54, 70.51), (1046.78, 44.73)),
    ('cubic', (1046.78, 44.73), (1023.01, 18.94), (992.77, 2.99), (956.05, -3.12)),
    ('cubic', (956.05, -3.12), (961.00, -10.55), (967.65, -15.89), (975.98, -19.14)),
    ('cubic', (975.98, -19.14), (995.25, -26.69), (1012.82, -30.47), (1028.71, -30.47)),
    ('line', (1028.71, -30.47), (1062.50, -30.47)),
    ('line', (1062.50, -30.47), (1054.10, -78.52)),
    ('line', (1054.10, -78.52), (1024.02, -78.52)),
    ('cubic', (1024.02, -78.52), (994.47, -78.52), (970.57, -71.03), (952.34, -56.05)),
    ('cubic', (952.34, -56.05), (939.32, -45.38), (930.01, -28.58), (924.41, -5.66)),
]


def test_an_axis_parallel_cluster_is_no_jog(monkeypatch):
    # the stems' clusters stay corners: one cubic over a flat run sags to the far side of
    # its points within the bound (the fifteenth session's sparse path 507 too). (Since
    # fit._SMOOTH_ALONG_SHARE the stems' smooth vertices move only along their long steps,
    # which holds this "M" either way: measured without it, the other places the guard
    # holds are in bench/RESULTS.md, sixteenth session)
    monkeypatch.setattr(fitmod, "_SMOOTH_ALONG_SHARE", 0.0)
    place = np.array([18753.5, 1243.0])
    d = _near(_M, _fit_rounded(_M)[1], place)
    monkeypatch.setattr(runs, "_CLUSTER_DIAG", 0.0)
    d_any = _near(_M, _fit_rounded(_M)[1], place)
    assert d < 0.6 and d_any > 0.8, (d, d_any)


def test_a_jog_is_never_beside_a_one_step_design_line(monkeypatch):
    # with jogs in every direction (a measurement setting), the cluster after the 30-unit
    # line would take the line into the curve's cubic (0.58 from the design here, 0.68 in
    # the bench's flattening of the font's quadratics) but for the one-step guard
    # (``runs._CLUSTER_STEPS``)
    place = np.array([1041.0, -79.2])
    monkeypatch.setattr(runs, "_CLUSTER_DIAG", 0.0)
    d = _near(_SBQ, _fit_rounded(_SBQ)[1], place)
    monkeypatch.setattr(runs, "_CLUSTER_STEPS", False)
    d_off = _near(_SBQ, _fit_rounded(_SBQ)[1], place)
    assert d < 0.45 and d_off > 0.55, (d, d_off)
