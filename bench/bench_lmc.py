"""LMC export benchmark (issue 19): on the bundled samples and the PLT corpus, process each
file (--fit-field, defaults), then

* encode the job as BJJCZ list records (ours, CPU time, median of 5) and with galvoplotter's
  GalvoController(mock=True) (its list packets captured, best of 3), and compare the two
  record for record (galvoplotter's goto() skips a jump to the point the beam is at and
  has no dot; we always jump and fire a dot: those jobs are compared again with galvoplotter
  writing the jump / laser-on point by hand);
* replay our list with the independent decoder and compare with the job's strokes;
* correct the job with a measured-3x3 field correction (a ~0.2 mm barrel error) and count
  the marks the subdivision adds.

Needs galvoplotter (the test extra). Prints a markdown table.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from galvo_core.correction import apply_to_job, from_3x3  # noqa: E402
from galvo_core.errors import GalvoError  # noqa: E402
from galvo_core.hpgl import read_file  # noqa: E402
from galvo_core.lmc import (  # noqa: E402
    END_OF_LIST,
    bits_per_mm,
    decode,
    encode_job,
    expected_strokes,
    job_pen_table,
    to_bytes,
)
from galvo_core.params import Params  # noqa: E402
from galvo_core.pipeline import Pipeline  # noqa: E402


def galvoplotter_encode(job, explicit_zero_jumps=False):  # noqa: ANN001, ANN201
    """The job through galvoplotter's API; ``explicit_zero_jumps``: also write, by hand
    (list_jump, list_laser_on_point), the two things goto()/mark() leave out: a jump to
    where the beam already is, and a one-mark stroke (a dot)."""
    import galvo

    table = job_pen_table(job)
    bpm = bits_per_mm(job)
    by_pen: dict[int, list] = {}
    for s in job.strokes:
        by_pen.setdefault(s.pen, []).append(s)
    layers = [table.settings(p) for p in sorted(by_pen)]
    la = layers[0].laser
    c = galvo.GalvoController(
        mock=True, galvos_per_mm=bpm, mark_speed=la.mark_speed_mm_s,
        travel_speed=la.jump_speed_mm_s, power=la.power_percent, frequency=la.frequency_khz,
        delay_laser_on=la.laser_on_delay_us, delay_laser_off=la.laser_off_delay_us,
        delay_polygon=la.polygon_delay_us, delay_jump_short=la.jump_delay_us,
        delay_jump_long=la.jump_delay_long_us)
    packets: list[bytes] = []

    def send(data, read=True):  # noqa: ANN001, ANN202
        if len(data) == 0xC00:
            packets.append(bytes(data))
        return (0, 0, 0, 0x20)

    c.send = send
    c.marking_configuration()
    for k, layer in enumerate(layers):
        lp = layer.laser
        if k:
            c.delay_polygon = lp.polygon_delay_us
            c.set(mark_speed=lp.mark_speed_mm_s, travel_speed=lp.jump_speed_mm_s,
                  power=lp.power_percent, frequency=lp.frequency_khz,
                  delay_on=lp.laser_on_delay_us, delay_off=lp.laser_off_delay_us)
        for _ in range(layer.passes):
            for s in by_pen[layer.pen]:
                m = s.marks
                x0, y0 = int(m[0, 0]), int(m[0, 1])
                if explicit_zero_jumps and (x0, y0) == c.get_last_xy():
                    # goto() would skip it: the same delay choice and jump, by hand
                    if lp.jump_delay_us:
                        c.set_delay_jump(lp.jump_delay_us)
                    c.list_jump(x0, y0)
                else:
                    c.goto(x0, y0, long=lp.jump_delay_long_us, short=lp.jump_delay_us,
                           distance_limit=lp.long_jump_mm * bpm)
                if explicit_zero_jumps and not (m[1:] != m[0]).any():
                    c.list_laser_on_point(1)  # a dot: goto() alone would not fire
                for x, y in m[1:]:
                    c.mark(int(x), int(y))
    c.initial_configuration()
    rec = np.frombuffer(b"".join(packets), dtype="<u2").reshape(-1, 6)
    n = len(rec)
    while n and rec[n - 1, 0] == END_OF_LIST and not rec[n - 1, 1:].any():
        n -= 1
    return np.vstack([rec[:n], [[END_OF_LIST, 0, 0, 0, 0, 0]]]).astype(np.uint16)


def cpu(fn, n):  # noqa: ANN001, ANN201
    ts = []
    out = None
    for _ in range(n):
        t0 = time.process_time()
        out = fn()
        ts.append(time.process_time() - t0)
    return out, ts


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--corpus", action="store_true", help="also the shared PLT corpus")
    ap.add_argument("--max-files", type=int, default=200)
    a = ap.parse_args()
    files = sorted((ROOT / "resources" / "samples").glob("*.plt"))
    if a.corpus:
        corpus = ROOT.parent / "shared" / "corpus" / "plt"
        files += sorted(p for p in corpus.iterdir() if p.suffix.lower() in (".plt", ".hpgl"))
    files = files[: a.max_files]
    pipe = Pipeline()
    e = np.zeros((3, 3, 2))
    for iy in range(3):
        for ix in range(3):
            e[iy, ix] = [(ix - 1) * (abs(iy - 1) + 1) * 120.0, (iy - 1) * (abs(ix - 1) + 1) * 120.0]
    corr = from_3x3(e, 60000.0)
    print("| file | strokes | marks | records | ours ms (median of 5) | galvoplotter ms (best "
          "of 3) | same records | decoder | corrected marks (+%), CPU (best of 3) |")
    print("|---|---:|---:|---:|---:|---:|---|---|---:|")
    tot_ours = tot_theirs = 0.0
    n_same = n_files = n_zero_jump = n_same_explicit = 0
    for f in files:
        try:
            d = read_file(f)
            job = pipe.run(d, Params(fit_field=True)).job
        except GalvoError:
            continue
        if not job.strokes:
            continue
        n_files += 1
        rec, ts = cpu(lambda job=job: encode_job(job), 5)
        theirs, tt = cpu(lambda job=job: galvoplotter_encode(job), 3)
        same = rec.shape == theirs.shape and bool((rec == theirs).all())
        # strokes starting where the beam already is (galvoplotter's goto() skips that
        # jump) and dots (it has no laser-on point in goto()/mark())
        zero = sum(1 for p, q in zip(job.strokes, job.strokes[1:], strict=False)
                   if (q.marks[0] == p.marks[-1]).all())
        zero += sum(1 for s in job.strokes if not (s.marks[1:] != s.marks[0]).any())
        dec = decode(to_bytes(rec))
        want = expected_strokes(job)
        ok = dec.ended and len(dec.strokes) == len(want) and all(
            np.array_equal(g.marks, m) for g, (_, m) in zip(dec.strokes, want, strict=True))
        marks = sum(len(s.marks) for s in job.strokes)
        try:
            cj, tc = cpu(lambda job=job: apply_to_job(job, corr), 3)
            cm = sum(len(s.marks) for s in cj.strokes)
            grow = f"{cm} (+{100 * (cm - marks) / marks:.1f}), {1000 * min(tc):.1f} ms"
        except GalvoError:
            grow = "leaves field"
        tot_ours += statistics.median(ts)
        tot_theirs += min(tt)
        n_same += same
        n_zero_jump += bool(zero)
        if same:
            verdict = "yes"
        else:
            t2 = galvoplotter_encode(job, explicit_zero_jumps=True)
            same2 = t2.shape == rec.shape and bool((t2 == rec).all())
            n_same_explicit += same2
            verdict = (f"{zero} zero-length jumps or dots; identical with them written"
                       if same2 else "NO")
        print(f"| {f.name[:48]} | {len(job.strokes)} | {marks} | {len(rec)} | "
              f"{1000 * statistics.median(ts):.2f} | {1000 * min(tt):.1f} | {verdict} | "
              f"{'exact' if ok else 'MISMATCH'} | {grow} |")
    print(f"\n{n_files} files: records identical to galvoplotter's on {n_same}; "
          f"{n_zero_jump} jobs have strokes starting where the previous one ended or dots, "
          f"identical on {n_same_explicit} of them when galvoplotter writes those by hand; "
          f"total encode CPU {1000 * tot_ours:.0f} ms (ours) vs {1000 * tot_theirs:.0f} ms "
          "(galvoplotter)")


if __name__ == "__main__":
    main()
