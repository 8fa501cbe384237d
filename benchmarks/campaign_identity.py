"""Whether two campaign output folders hold the same results, to the digit.

``python benchmarks/campaign_identity.py REF CAND`` compares every ``.csv``,
``.md`` and ``.json`` file under the two folders (the tables, the metrics, the
report, the exports' metadata, the stage cache's entries) and prints one line
per file that differs, is missing or is extra, then a verdict. Exit status 0
when every file is the same, 1 otherwise.

Files are compared byte for byte, except what a run's machine and folder
change and no result depends on, which is dropped from both sides first:

- the ``wall_s``, ``build_s``, ``wall_per_sim_s`` and ``real_time_factor``
  columns of a ``.csv`` (the runs' own times: ``metrics*.csv``, ``efficiency.csv``);
- ``timings.json``, ``efficiency.csv`` and ``cache/efficiency.json`` whole
  (wall times and nothing else; only their presence is compared), and in any
  other ``.json`` every key of :data:`TIMED_KEYS`: times, the output folder's
  paths and files' modification times, and the code fingerprints and stage keys
  (``key``, ``generator``: they change with any edit of artic's code, the
  results not);
- in ``report.md``: the lines that quote wall times, the code fingerprint or
  the output folder (the efficiency figures, the closing lines), matched by
  :data:`TIMED_LINE`, the sections of :data:`TIMED_SECTIONS` whole (the
  efficiency table, the stage table), and the tuning table's wall-time cell
  (the cell before a row's closing ``ok``); the report's other lines are compared.

Everything else must be identical byte for byte.
"""

from __future__ import annotations

import argparse
import io
import json
import re
import sys
from pathlib import Path

SUFFIXES = (".csv", ".md", ".json")
TIMED_COLUMNS = ("wall_s", "build_s", "wall_per_sim_s", "real_time_factor")
TIMED_KEYS = ("wall_s", "build_s", "path", "outputs", "stages", "mtime_ns", "key", "generator")
SKIP = ("timings.json",)
PRESENCE = ("efficiency.csv", "cache/efficiency.json")
TIMED_LINE = re.compile(r"( s\b| s;| s\)|wall|Wall|real.time|/tmp/|\bms\b|per simulated|"
                        r"\(code [0-9a-f]+\)|Efficiency)")
TIMED_SECTIONS = ("## Computational efficiency", "## Wall time by stage")
TUNING_ROW = re.compile(r"\| [^|]* \| ok \|$")


def _csv(text: str) -> str:
    import pandas as pd

    frame = pd.read_csv(io.StringIO(text), dtype=str, keep_default_na=False)
    frame = frame.drop(columns=[c for c in frame.columns if c in TIMED_COLUMNS])
    return frame.to_csv(index=False)


def _json(value):
    if isinstance(value, dict):
        return {k: _json(v) for k, v in value.items() if k not in TIMED_KEYS}
    if isinstance(value, list):
        return [_json(v) for v in value]
    return value


def normalised(path: Path, root: Path) -> str:
    """The file's text with the timing fields dropped (see the module docstring)."""
    text = path.read_text(encoding="utf-8", errors="replace").replace(str(root), "OUT")
    if path.suffix == ".csv":
        head = text.split("\n", 1)[0].split(",")
        return _csv(text) if any(c in TIMED_COLUMNS for c in head) else text
    if path.suffix == ".json":
        try:
            return json.dumps(_json(json.loads(text)), sort_keys=True, indent=1)
        except ValueError:
            return text
    if path.name == "report.md":
        kept, timed = [], False
        for line in text.splitlines():
            if line.startswith("## "):
                timed = line in TIMED_SECTIONS
            if not timed and not TIMED_LINE.search(line):
                kept.append(TUNING_ROW.sub("| - | ok |", line))
        return "\n".join(kept)
    return text


def files(root: Path) -> dict[str, Path]:
    """The compared files under ``root``, by their path relative to it."""
    return {str(p.relative_to(root)): p for p in sorted(root.rglob("*"))
            if p.is_file() and p.suffix in SUFFIXES and p.name not in SKIP}


def compare(ref: Path, cand: Path) -> list[str]:
    """One line per differing, missing or extra file (empty: identical)."""
    a, b = files(ref), files(cand)
    out = []
    for name in sorted(a.keys() | b.keys()):
        if name not in b:
            out.append(f"{name}: missing from {cand}")
        elif name not in a:
            out.append(f"{name}: extra in {cand}")
        elif name in PRESENCE or a[name].read_bytes() == b[name].read_bytes():
            continue
        else:
            x, y = normalised(a[name], ref), normalised(b[name], cand)
            if x != y:
                first = next((i for i, (p, q) in enumerate(zip(x.splitlines(), y.splitlines(),
                                                                  strict=False)) if p != q),
                             min(len(x.splitlines()), len(y.splitlines())))
                out.append(f"{name}: differs (first at line {first + 1})")
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("ref", type=Path)
    parser.add_argument("cand", type=Path)
    a = parser.parse_args(argv)
    lines = compare(a.ref, a.cand)
    for line in lines:
        print(line)
    n = len(files(a.ref))
    print(f"identical: {n} files" if not lines else f"DIFFERENT: {len(lines)} of {n} files")
    return 1 if lines else 0


if __name__ == "__main__":
    sys.exit(main())
