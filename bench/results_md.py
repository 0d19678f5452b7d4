"""Replace one ``## ...`` section of bench/RESULTS.md, leaving the others as they are."""

from __future__ import annotations

import os
from pathlib import Path

RESULTS = Path(__file__).resolve().parent / "RESULTS.md"


def replace_section(head: str, text: str, path: str | os.PathLike[str] = RESULTS) -> None:
    """Put ``text`` (which starts with the line ``head``) in place of the section that starts
    with ``head`` — up to the next ``## `` heading — or append it. Written atomically, so a
    benchmark running beside another never leaves a half-written file."""
    p = Path(path)
    old = p.read_text(encoding="utf-8") if p.exists() else "# Benchmark results\n"
    start = old.find(head + "\n")
    if start < 0 and old.endswith(head):
        start = len(old) - len(head)
    if start >= 0:
        nxt = old.find("\n## ", start + len(head))
        new = old[:start] + text.rstrip("\n") + "\n" + (old[nxt:] if nxt >= 0 else "")
    else:
        new = old.rstrip("\n") + "\n\n" + text.rstrip("\n") + "\n"
    tmp = p.with_name(f".{p.name}.tmp-{os.getpid()}")
    tmp.write_text(new, encoding="utf-8")
    os.replace(tmp, p)
