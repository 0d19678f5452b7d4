"""Are the jobs the same before and after a change? (issue 21: "the job's marks unchanged")

Writes every job of a fixed set of files and option sets with the CLI, both forms (v1 JSON
and v2 .gjob), into a folder; then compares two such folders byte for byte::

    python bench/compare_jobs.py write bench/out/jobs_before     # on the old commit
    python bench/compare_jobs.py write bench/out/jobs_after      # on the new one
    python bench/compare_jobs.py diff bench/out/jobs_before bench/out/jobs_after

The files: the bundled samples and a few corpus drawings of different kinds; the option sets:
``--fit-field`` (the default pipeline), a fixed magnification, zig-zag fill with kerf and the
optimized order, the greedy order, and the raw marks. ``diff`` exits 1 (naming them) when any
job differs.
"""

from __future__ import annotations

import argparse
import contextlib
import filecmp
import io
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
CORPUS = Path("/work/shared/corpus/plt")
SAMPLES = ROOT / "resources" / "samples"

CORPUS_FILES = (
    "adelrune__hpgl-to-svg__megablueprintv1.hpgl",
    "h42i__monoplots__noten.hpgl",
    "drepetto__chiplotle__foal_release-0.1.hpgl",
    "vk2bea__hpgl-plotter__space-shuttle.hpgl",
    "temagrin__kicadhpgl2gcode__laser-b_cu.plt",
    "dgtlrift__hp2xx__acad.hp",
)
OPTIONS = {
    "fit": ["--fit-field"],
    "mag": ["--magnification", "20", "--clamp"],
    "fill": ["--fit-field", "--fill", "zigzag", "--hatch-spacing-mm", "0.2", "--kerf-mm",
             "0.05", "--scan-order", "optimized"],
    "greedy": ["--fit-field", "--scan-order", "greedy"],
    "raw": ["--fit-field", "--interpolation", "raw"],
}


def files() -> list[Path]:
    out = sorted(SAMPLES.glob("*.plt"))
    out += [CORPUS / f for f in CORPUS_FILES if (CORPUS / f).exists()]
    return out


def write(folder: Path) -> int:
    sys.path.insert(0, str(ROOT))
    from galvo_core.cli import main

    folder.mkdir(parents=True, exist_ok=True)
    n = 0
    for f in files():
        for tag, opts in OPTIONS.items():
            for ext in ("json", "gjob"):
                out = folder / f"{f.stem}.{tag}.{ext}"
                with contextlib.redirect_stdout(io.StringIO()):
                    rc = main(["process", str(f), "-o", str(out), *opts])
                if rc != 0:
                    print(f"{f.name} {tag}: exit {rc}", file=sys.stderr)
                    out.write_bytes(f"exit {rc}".encode())
                n += 1
    print(f"{n} jobs written to {folder}")
    return 0


def diff(a: Path, b: Path) -> int:
    names = sorted({p.name for p in a.iterdir()} | {p.name for p in b.iterdir()})
    bad = [n for n in names if not ((a / n).exists() and (b / n).exists()
                                    and filecmp.cmp(a / n, b / n, shallow=False))]
    for n in bad:
        print(f"differs: {n}")
    print(f"{len(names) - len(bad)} of {len(names)} jobs byte for byte the same")
    return 1 if bad else 0


def main_(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    w = sub.add_parser("write")
    w.add_argument("folder", type=Path)
    d = sub.add_parser("diff")
    d.add_argument("a", type=Path)
    d.add_argument("b", type=Path)
    a = ap.parse_args(argv)
    return write(a.folder) if a.cmd == "write" else diff(a.a, a.b)


if __name__ == "__main__":
    raise SystemExit(main_())
