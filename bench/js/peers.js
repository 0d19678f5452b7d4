// Fit peers for bench/bench_fit.py and bench/bench_precision_peers.py. stdin: JSON {lib,
// scale, tols: [...], paths: [{closed, points: [[x, y], ...]}]}; stdout: JSON {version, results: [{tol, ms, paths: [[[x0, y0],
// [x1, y1], [x2, y2], [x3, y3]], ...]]}]} (cubics in the input's units).
// Coordinates are multiplied by `scale` before fitting and divided after: Paper.js skips its
// refinement when tolerance^2 < 1, so the tolerances handed over must be >= 1 after scaling.
// Both peers compare the number handed over with SQUARED distances (fit-curve's maxError;
// Paper.js's PathFitter.findMaxError returns a squared distance and fitCubic compares it with
// the tolerance as given): a distance d is handed over as (d * scale)^2
// (bench_precision_peers.py; bench_fit.py searches the tolerance, whatever its meaning).
'use strict';
const fs = require('fs');
const inp = JSON.parse(fs.readFileSync(0, 'utf8'));
const S = inp.scale;
let version;
let fitOne;
if (inp.lib === 'fit-curve') {
  const fitCurve = require('fit-curve');
  version = require('fit-curve/package.json').version;
  fitOne = (pts, closed, tol) => fitCurve(pts, tol);
} else {
  const paper = require('paper');
  version = require('paper/package.json').version;
  paper.setup(new paper.Size(1, 1));
  fitOne = (pts, closed, tol) => {
    const path = new paper.Path({ segments: pts, closed: false, insert: false });
    if (closed) path.closed = true;
    path.simplify(tol);
    return path.curves.map((c) => c.points.map((p) => [p.x, p.y]));
  };
}
const paths = inp.paths.map((p) => ({ closed: p.closed, pts: p.points.map(([x, y]) => [x * S, y * S]) }));
const results = [];
for (const tol of inp.tols) {
  const t0 = process.hrtime.bigint();
  const out = paths.map((p) => (p.pts.length < 2 ? [] : fitOne(p.pts, p.closed, tol)));
  const ms = Number(process.hrtime.bigint() - t0) / 1e6;
  results.push({ tol, ms, paths: out.map((cs) => cs.map((c) => c.map(([x, y]) => [x / S, y / S]))) });
}
process.stdout.write(JSON.stringify({ version, results }));
