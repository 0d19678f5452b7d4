"""Pipeline throughput (issue 21): the whole job, end to end, from 10 k to 5 M points.

One command::

    python bench/bench_pipeline.py                 # everything; rewrites "## Pipeline throughput"
    python bench/bench_pipeline.py --sizes 10000 100000 --runs 1 --no-write
    python bench/bench_pipeline.py --kinds generated --fill off

For each drawing kind (``generated``: bench/gen_plt.py's random CAD-style file;
``real``: the PLT corpus (/work/shared/corpus/plt, MANIFEST.tsv) and the bundled samples,
each drawing's share of the points in whole paths, side by side on a grid: the same mix of
drawings and paths per point at every size, see ``real``), size
and fill setting (off; ``zigzag`` with kerf and optimized order), it measures:

* **end to end through the CLI**: ``galvo-core process FILE -o JOB.gjob --fit-field`` (and
  the same with ``-o JOB.json``, the version 1 JSON) in a fresh subprocess: wall time, CPU
  time (user + system of the child, ``os.wait4``) and the child's peak resident memory;
* **per stage**, in another fresh subprocess (the same calls the pipeline makes, each
  timed where ``galvo_core.pipeline`` calls it): read, kerf, fit, sample, fill, hatch marks,
  order, the remaining glue of ``Pipeline.run`` (strokes, stats), write (.gjob), load (.gjob):
  wall and CPU (``time.process_time``) and the peak RSS reached by the end of the stage.

Each number is the median of ``--runs`` runs (3 by default) up to 100 k points,
``--runs-1m`` (3) up to 1 M, ``--runs-5m`` (1) above; ``--section`` names the RESULTS.md
heading written (the fourth round wrote "## Pipeline throughput, fourth round (issue 21,
s3)"). The growth exponent of a stage between two sizes is log(t2/t1)/log(n2/n1) of its
CPU time; the table gives it from 100 k to the largest size (stages under 20 ms at both ends
are not rated: their times are noise). The machine is shared: CPU times are the ones to
compare.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
OUT = HERE / "out" / "pipeline"
CORPUS = Path("/work/shared/corpus")
SAMPLES = ROOT / "resources" / "samples"
PY = sys.executable

SECTION = "## Pipeline throughput (issue 21)"
STAGES = ("read", "kerf", "fit", "sample", "fill", "hatch_marks", "order", "glue", "write",
          "load")
FILL_PARAMS = {"fill": "zigzag", "hatch_spacing_mm": 0.1, "kerf_mm": 0.05,
               "scan_order": "optimized"}
FILL_ARGS = [x for k, v in FILL_PARAMS.items() for x in ("--" + k.replace("_", "-"), str(v))]


# ------------------------------------------------------------------------ inputs
def generated(n: int) -> Path:
    sys.path.insert(0, str(HERE))
    from gen_plt import generate_plt

    p = OUT / f"gen_{n}.plt"
    if not p.exists():
        p.write_bytes(generate_plt(n, 0))
    return p


def _real_paths() -> list[list[np.ndarray]]:
    """Every readable corpus file and sample as a list of pen-down paths (input units)."""
    sys.path.insert(0, str(ROOT))
    from galvo_core.errors import GalvoError
    from galvo_core.hpgl import read_file

    files = []
    man = CORPUS / "MANIFEST.tsv"
    if man.exists():
        for line in man.read_text(encoding="utf-8").splitlines()[1:]:
            f = line.split("\t")[0]
            if f.endswith((".plt", ".hpgl", ".hgl", ".pcl", ".prn", ".plo")):
                files.append(CORPUS / f)
    files += sorted(SAMPLES.glob("*.plt"))
    out = []
    for f in files:
        try:
            d = read_file(f)
        except (GalvoError, OSError):
            continue
        paths = [np.asarray(p.points) for p in d.paths if len(p.points) >= 2]
        if paths:
            out.append(paths)
    return out


def real(n: int) -> Path:
    """About ``n`` points of real drawings with the same mix at every size.

    The pool: every readable corpus file and sample (64 drawings, 0.9 M points, 150 k paths).
    Drawing ``k`` gets its share ``n * P_k / P`` of the points (``P_k`` its points, ``P``
    the pool's): as many whole copies as fit, then whole paths in a fixed pseudo-random
    order of that drawing's paths (the same order at every size) while they bring the share
    nearer. So the paths per point, the path lengths and each drawing's share are the same
    from 10 k to 5 M points (up to one path per drawing), instead of changing with the size.
    Paths stay whole (closed paths stay closed: fill regions stay real). Each copy of a
    drawing sits in its own 4000 x 4000 unit cell, scaled with its drawing as a whole
    (integer coordinates): drawing ``k`` in column ``k`` of 64, copy ``c`` in row ``c``, so
    the sheet is 64 cells wide at every size and ``--fit-field`` gives the same
    magnification (the largest drawings at the two ends keep both edges filled)."""
    p = OUT / f"real_mix_{n}.plt"
    if p.exists():
        return p
    pool = sorted(_real_paths(), key=lambda ps: sum(len(q) for q in ps), reverse=True)
    # the two largest drawings at the two ends of the row: both edges filled at 10 k too
    pool = [pool[0]] + pool[2:] + [pool[1]]
    rng = np.random.default_rng(21)
    sizes = [np.array([len(q) for q in ps]) for ps in pool]
    total = sum(int(s.sum()) for s in sizes)
    cell = 4000.0
    cols = max(64, len(pool))
    rows: list[list[tuple[int, np.ndarray]]] = []  # per row (copy): (column, path in cell)
    for k, paths in enumerate(pool):
        allp = np.concatenate(paths)
        lo, hi = allp.min(axis=0), allp.max(axis=0)
        s = 0.9 * cell / max(float((hi - lo).max()), 1e-9)
        perm = rng.permutation(len(paths))
        share = n * float(sizes[k].sum()) / total
        full = int(share // sizes[k].sum())
        left = share - full * float(sizes[k].sum())
        chosen = [list(range(len(paths)))] * full
        part = []
        for i in perm:  # whole paths while they bring the share nearer (a prefix of the
            if sizes[k][i] > 2 * left:  # order: no bias towards short paths)
                break
            part.append(int(i))
            left -= sizes[k][i]
        if part:
            chosen.append(sorted(part))  # a copy's paths in the drawing's own order
        for c, idx in enumerate(chosen):
            while len(rows) <= c:
                rows.append([])
            off = np.array([k * cell, c * cell]) + 0.05 * cell
            for i in idx:
                rows[c].append((k, np.rint((paths[i] - lo) * s + off).astype(np.int64)))
    assert len(rows) <= cols, "more copies than columns: the sheet's height would set the scale"
    parts = ["IN;SP1;\n"]
    for row in rows:
        for _, r in row:
            rest = ",".join(map(str, r[1:].ravel().tolist()))
            parts.append(f"PU{r[0, 0]},{r[0, 1]};PD{rest};\n")
    parts.append("PU;SP0;\n")
    p.write_text("".join(parts), encoding="ascii")
    return p


# ------------------------------------------------------------------- measurement
def _child(cmd: list[str]) -> dict[str, float]:
    """Run ``cmd``; wall, CPU (user + sys) and peak RSS (MB) of that child alone."""
    env = dict(os.environ, PYTHONPATH=str(ROOT), QT_QPA_PLATFORM="offscreen")
    # output to files, read after the child ends: a pipe that fills up (the CLI's stats and
    # warnings of a large job) would block the child while this waits for it
    with tempfile.TemporaryFile() as fo, tempfile.TemporaryFile() as fe:
        t0 = time.perf_counter()
        proc = subprocess.Popen(cmd, stdout=fo, stderr=fe, env=env)
        _, status, ru = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - t0
        fo.seek(0)
        fe.seek(0)
        out = fo.read().decode()
        err = fe.read().decode()
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({proc.returncode}): {err.strip()[-400:]}")
    return {"wall": wall, "cpu": ru.ru_utime + ru.ru_stime, "rss_mb": ru.ru_maxrss / 1024,
            "stdout": out}  # type: ignore[dict-item]


def cli_run(src: Path, out: Path, fill: bool) -> dict[str, float]:
    cmd = [PY, "-m", "galvo_core.cli", "process", str(src), "-o", str(out), "--fit-field"]
    if fill:
        cmd += FILL_ARGS
    r = _child(cmd)
    r.pop("stdout")
    return r


def stage_run(src: Path, out: Path, fill: bool) -> dict[str, dict[str, float]]:
    cmd = [PY, str(Path(__file__).resolve()), "--stage-worker", str(src), str(out)]
    if fill:
        cmd.append("--fill-on")
    r = _child(cmd)
    return json.loads(r["stdout"])  # type: ignore[arg-type]


def worker(src: str, out: str, fill: bool) -> None:
    """One instrumented job: every stage function timed where the pipeline calls it."""
    sys.path.insert(0, str(ROOT))
    import galvo_core.pipeline as pl
    from galvo_core.fit import warm_up
    from galvo_core.hpgl import read_file
    from galvo_core.job import load_job, write_job
    from galvo_core.params import Params

    warm_up()  # compiled kernels loaded (not counted: the CLI pays it once at import)
    acc = {s: [0.0, 0.0, 0.0, 0.0] for s in STAGES}  # wall, CPU, peak RSS, user CPU

    def rss() -> float:
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024

    def timed(stage: str, fn):  # type: ignore[no-untyped-def]
        def wrap(*a, **k):  # type: ignore[no-untyped-def]
            w, c, u = time.perf_counter(), time.process_time(), os.times().user
            try:
                return fn(*a, **k)
            finally:
                acc[stage][0] += time.perf_counter() - w
                acc[stage][1] += time.process_time() - c
                acc[stage][2] = rss()
                acc[stage][3] += os.times().user - u
        return wrap

    names = {"kerf": "compensate_indexed", "fit": "fit_drawing", "sample": "sample_paths",
             "fill": "hatch", "hatch_marks": "polyline_marks", "order": "order_job_strokes"}
    for stage, name in names.items():
        if hasattr(pl, name):
            setattr(pl, name, timed(stage, getattr(pl, name)))
    params = Params(fit_field=True, **(FILL_PARAMS if fill else {}))
    d = timed("read", read_file)(src)
    w, c, u = time.perf_counter(), time.process_time(), os.times().user
    job = pl.Pipeline().run(d, params).job
    run_w, run_c = time.perf_counter() - w, time.process_time() - c
    run_u = os.times().user - u
    inner = [s for s in names]
    acc["glue"] = [run_w - sum(acc[s][0] for s in inner), run_c - sum(acc[s][1] for s in inner),
                   rss(), run_u - sum(acc[s][3] for s in inner)]
    timed("write", write_job)(job, out)
    counts = {"points": d.n_points, "paths": len(d.paths), "strokes": len(job.strokes),
              "marks": int(sum(len(s.marks) for s in job.strokes))}
    del job
    timed("load", load_job)(out)
    res = {s: {"wall": v[0], "cpu": v[1], "rss_mb": v[2], "user": v[3]}
           for s, v in acc.items()}
    res["_"] = counts
    print(json.dumps(res))


def io_bench(n_marks: int, runs: int) -> dict[str, float]:
    """Write and load a job of ``n_marks`` marks in both forms (CPU and wall, best of
    ``runs``): strokes of 400 marks with a line per two marks and a cubic per 40, the shape
    of the generated drawings' jobs."""
    sys.path.insert(0, str(ROOT))
    from galvo_core.field import FieldMap
    from galvo_core.job import Job, Segments, Stroke, load_job, write_job

    rng = np.random.default_rng(1)
    fm = FieldMap(4.0, (100.0, 100.0), 65536, 110.0)
    per = 400
    strokes = []
    for k in range(max(1, n_marks // per)):
        m = rng.integers(0, 65536, (per, 2))
        kinds = rng.random(per // 2) < 0.05
        pts = rng.uniform(0, 16000, (1 + int(np.where(kinds, 3, 1).sum()), 2))
        strokes.append(Stroke("contour", k, False, m, Segments(kinds, pts)))
    job = Job("io.plt", "0" * 64, fm, {}, {}, tuple(strokes), {}, ())
    out: dict[str, float] = {"marks": float(per * len(strokes))}
    for ext in ("gjob", "json"):
        path = OUT / f"io.{ext}"
        for op in ("write", "load"):
            best_c = best_w = math.inf
            for _ in range(runs if ext == "gjob" else 1):
                w, c = time.perf_counter(), time.process_time()
                if op == "write":
                    write_job(job, path)
                else:
                    load_job(path)
                best_c = min(best_c, time.process_time() - c)
                best_w = min(best_w, time.perf_counter() - w)
            out[f"{ext}_{op}_cpu"] = best_c
            out[f"{ext}_{op}_wall"] = best_w
        out[f"{ext}_mb"] = path.stat().st_size / 1e6
    return out


# ------------------------------------------------------------------------ report
def exponent(n1: int, t1: float, n2: int, t2: float) -> float | None:
    if max(t1, t2) < 0.02 or t1 <= 0 or t2 <= 0:
        return None
    return math.log(t2 / t1) / math.log(n2 / n1)


def med(rows: list[dict[str, float]], key: str) -> float:
    return statistics.median(r[key] for r in rows)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000, 1_000_000,
                                                             5_000_000])
    ap.add_argument("--kinds", nargs="+", default=["generated", "real"])
    ap.add_argument("--fill", nargs="+", default=["off", "on"])
    ap.add_argument("--fill-max", type=int, default=1_000_000,
                    help="largest size run with fill on (default 1 M)")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--runs-1m", type=int, default=3,
                    help="runs above 100 k up to 1 M points")
    ap.add_argument("--runs-5m", type=int, default=1, help="runs above 1 M points")
    ap.add_argument("--section", default=SECTION,
                    help=f"the RESULTS.md heading to write (default {SECTION!r})")
    ap.add_argument("--no-write", action="store_true")
    ap.add_argument("--io-marks", type=int, default=5_000_000,
                    help="marks of the job-file write/load measurement (0: skip)")
    ap.add_argument("--from-json", metavar="RESULTS_JSON", nargs="+",
                    help="only write the section from the results.json of earlier runs "
                    "(several: their rows in turn, the job-file I/O of the last that has it)")
    ap.add_argument("--stage-worker", nargs=2, metavar=("SRC", "OUT"))
    ap.add_argument("--fill-on", action="store_true")
    ap.add_argument("--io-worker", nargs=2, type=int, metavar=("MARKS", "RUNS"))
    ap.add_argument("--gen-worker", nargs=2, metavar=("KIND", "N"))
    a = ap.parse_args(argv)
    if a.stage_worker:
        worker(a.stage_worker[0], a.stage_worker[1], a.fill_on)
        return 0
    if a.io_worker:
        OUT.mkdir(parents=True, exist_ok=True)
        print(json.dumps(io_bench(a.io_worker[0], a.io_worker[1])))
        return 0
    if a.gen_worker:
        OUT.mkdir(parents=True, exist_ok=True)
        n = int(a.gen_worker[1])
        print(generated(n) if a.gen_worker[0] == "generated" else real(n))
        return 0
    if a.from_json:
        saves = [json.loads(Path(f).read_text()) for f in a.from_json]
        rows = [r for sv in saves for r in sv["results"]]
        io_s = next((sv["io"] for sv in reversed(saves) if sv.get("io")), None)
        text = report(rows, io_s, saves[-1].get("meta"), a.section)
        print(text)
        if not a.no_write:
            sys.path.insert(0, str(HERE))
            from results_md import replace_section

            replace_section(a.section, text)
        return 0
    OUT.mkdir(parents=True, exist_ok=True)
    # every measurement in a fresh child of this small process: a child's peak RSS
    # (ru_maxrss) starts from its parent's at the fork, so the parent stays small
    io = None
    if a.io_marks:
        r = _child([PY, str(Path(__file__).resolve()), "--io-worker", str(a.io_marks),
                    str(a.runs)])
        io = json.loads(r["stdout"])  # type: ignore[arg-type]
    if io:
        print("job file I/O:", json.dumps(io), flush=True)
    results = []
    for fill in a.fill:  # fill off first: the long fill runs last
        for kind in a.kinds:
            for n in a.sizes:
                if fill == "on" and n > a.fill_max:
                    continue
                src = Path(_child([PY, str(Path(__file__).resolve()), "--gen-worker", kind,
                                   str(n)])["stdout"].strip())  # type: ignore[union-attr]
                runs = a.runs if n <= 100_000 else (a.runs_1m if n <= 1_000_000 else a.runs_5m)
                on = fill == "on"
                e2e = [cli_run(src, OUT / "job.gjob", on) for _ in range(runs)]
                # the v1 JSON end to end only without fill (the same stages but the writer)
                e2e_json = e2e if on else [cli_run(src, OUT / "job.json", on)
                                           for _ in range(runs)]
                st = [stage_run(src, OUT / "stage.gjob", on) for _ in range(runs)]
                row = {
                    "kind": kind, "fill": fill, "n": n, "runs": runs,
                    "gjob": {k: med(e2e, k) for k in ("wall", "cpu", "rss_mb")},
                    "json": {k: med(e2e_json, k) for k in ("wall", "cpu", "rss_mb")},
                    "stages": {s: {k: statistics.median(r[s][k] for r in st)
                                   for k in ("wall", "cpu", "rss_mb", "user")}
                               for s in STAGES},
                    "counts": st[0]["_"],
                    "gjob_bytes": (OUT / "job.gjob").stat().st_size,
                    "json_bytes": (OUT / "job.json").stat().st_size if not on else 0,
                }
                results.append(row)
                g = row["gjob"]
                print(f"{kind:9s} fill {fill:3s} {n:>9,d}: .gjob {g['wall']:.2f} s wall "
                      f"{g['cpu']:.2f} s CPU {g['rss_mb']:.0f} MB; .json "
                      f"{row['json']['wall']:.2f} s wall; stages CPU "
                      + " ".join(f"{s}={row['stages'][s]['cpu']:.2f}" for s in STAGES),
                      flush=True)
                (OUT / "results.json").write_text(json.dumps(
                    {"results": results, "io": io, "meta": meta()}, indent=1))
    text = report(results, io, meta(), a.section)
    print(text)
    if not a.no_write:
        sys.path.insert(0, str(HERE))
        from results_md import replace_section

        replace_section(a.section, text)
    return 0


def meta() -> dict[str, str]:
    import platform

    return {"date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
            "python": platform.python_version(), "numpy": np.__version__,
            "cores": str(os.cpu_count()), "load": f"{os.getloadavg()[0]:.1f}"}


def _exponent_rows(kind: str, fill: str, a: dict, b: dict,  # type: ignore[type-arg]
                   full: bool) -> list[str]:
    """The exponent rows of one drawing kind and fill setting between sizes ``a`` and ``b``:
    CPU against the points read, and (``full``) user time and CPU against the strokes."""
    lines = []
    na, nb = a.get("counts", {}).get("strokes", 0), b.get("counts", {}).get("strokes", 0)
    pa = a.get("counts", {}).get("points") or a["n"]
    pb = b.get("counts", {}).get("points") or b["n"]
    measures = [("CPU", "cpu", pa, pb)]
    if full and any("user" in a["stages"][s] for s in STAGES):
        measures.append(("user", "user", pa, pb))
    if full and na and nb and na != nb:
        measures.append((f"per stroke ({na:,} → {nb:,})", "cpu", na, nb))
    for label, key, xa, xb in measures:
        cells = []
        for s in STAGES:
            e = exponent(xa, a["stages"][s].get(key, 0.0), xb, b["stages"][s].get(key, 0.0))
            cells.append("—" if e is None else f"{e:.2f}")
        e = exponent(xa, a["gjob"]["cpu"], xb, b["gjob"]["cpu"]) if key == "cpu" else None
        lines.append(f"| {kind} | {fill} | {a['n']:,} → {b['n']:,} | {label} | "
                     + " | ".join(cells) + f" | {'—' if e is None else f'{e:.2f}'} |")
    return lines


def report(results: list[dict], io: dict[str, float] | None,  # type: ignore[type-arg]
           m: dict[str, str] | None = None, section: str = "") -> str:
    m = m or meta()
    by_size: dict[int, set[int]] = {}
    for r in results:
        by_size.setdefault(r["n"], set()).add(r["runs"])
    runs_text = ", ".join(f"{'/'.join(map(str, sorted(v)))} at {n:,}"
                          for n, v in sorted(by_size.items()))
    lines = [
        section or SECTION,
        "",
        f"`python bench/bench_pipeline.py` on {m['date']}, Python {m['python']}, numpy "
        f"{m['numpy']}, {m['cores']} cores shared with other sessions (load average "
        f"{m['load']} at the end): wall times are "
        "inflated by the load, CPU times are the ones to compare. End to end = "
        "`galvo-core process FILE -o JOB.gjob|JOB.json --fit-field` in a fresh process "
        "(child's wall, user + system CPU, peak RSS); fill on = `" + " ".join(FILL_ARGS) +
        "` (its .json column repeats the .gjob run: not measured separately). Median of the "
        f"runs given (runs per size: {runs_text} points).",
        "",
        "### End to end through the CLI",
        "",
        "| drawing | fill | points | runs | .gjob wall s | .gjob CPU s | peak MB | .json wall s "
        "| .json CPU s | .gjob MB | .json MB |",
        "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for r in results:
        g, j = r["gjob"], r["json"]
        lines.append(f"| {r['kind']} | {r['fill']} | {r['n']:,} | {r['runs']} | {g['wall']:.2f} "
                     f"| {g['cpu']:.2f} | {g['rss_mb']:.0f} | {j['wall']:.2f} | {j['cpu']:.2f} "
                     f"| {r['gjob_bytes'] / 1e6:.1f} | {r['json_bytes'] / 1e6:.1f} |")
    lines += ["", "### CPU seconds per stage (peak RSS MB at the end of the job)", "",
              "| drawing | fill | points | points read | paths | paths / 1 k points | strokes | "
              + " | ".join(STAGES) + " | peak MB |",
              "| --- | --- | ---: | ---: | ---: | ---: | ---: |" + " ---: |" * (len(STAGES) + 1)]
    for r in results:
        st = r["stages"]
        c = r.get("counts", {})
        pts, paths = c.get("points", 0), c.get("paths", 0)
        per = f"{1000 * paths / pts:.1f}" if pts else "—"
        read = f"{pts:,}" if pts else "—"
        lines.append(f"| {r['kind']} | {r['fill']} | {r['n']:,} | {read} | {paths:,} | {per} | "
                     f"{c.get('strokes', 0):,} | "
                     + " | ".join(f"{st[s]['cpu']:.3f}" for s in STAGES)
                     + f" | {max(st[s]['rss_mb'] for s in STAGES):.0f} |")
    lines += ["", "### Growth exponent per stage (from 100 k points to the largest size, and "
              "between the two largest; — under 20 ms)", "",
              "CPU: user + system time against the points; user: user time alone (without "
              "the kernel's work, mostly zeroing fresh pages); per stroke: CPU time against "
              "the job's strokes. Against the points read (within 2 % of the size asked for: "
              "the real drawings take whole paths). The real drawings have the same mix at "
              "every size (paths per point in the table above).", "",
              "| drawing | fill | sizes | measure | " + " | ".join(STAGES) + " | end to end |",
              "| --- | --- | --- | --- |" + " ---: |" * (len(STAGES) + 1)]
    groups: dict[tuple[str, str], list[dict]] = {}  # type: ignore[type-arg]
    for r in results:
        groups.setdefault((r["kind"], r["fill"]), []).append(r)
    for (kind, fill), rows in groups.items():
        rows = [r for r in rows if r["n"] >= 100_000]
        if len(rows) < 2:
            continue
        pairs = [(rows[0], rows[-1], True)]
        if len(rows) > 2:  # and between the two largest sizes (CPU only)
            pairs.append((rows[-2], rows[-1], False))
        for a, b, full in pairs:
            lines += _exponent_rows(kind, fill, a, b, full)
    if io:
        lines += ["", f"### Job file: writing and loading {io['marks']:,.0f} marks", "",
                  "A synthetic job (strokes of 400 marks, a line per two marks, a cubic per 40: "
                  "the shape of the generated drawings' jobs); CPU and wall seconds, best of "
                  "the runs (.json: one run).", "",
                  "| form | MB | write CPU s | write wall s | load CPU s | load wall s |",
                  "| --- | ---: | ---: | ---: | ---: | ---: |"]
        for ext, name in (("gjob", "version 2, .gjob"), ("json", "version 1, .json")):
            lines.append(f"| {name} | {io[ext + '_mb']:.1f} | {io[ext + '_write_cpu']:.2f} | "
                         f"{io[ext + '_write_wall']:.2f} | {io[ext + '_load_cpu']:.2f} | "
                         f"{io[ext + '_load_wall']:.2f} |")
    lines.append("")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    raise SystemExit(main())
