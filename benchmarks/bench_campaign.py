"""The whole default campaign, from nothing, with the wall time of each stage.

Runs the main job (``artic campaign``) into a fresh temporary folder with one
job per core: generation of the 58 synthetic manoeuvres on the plant, tuning
of KIN, STM and MBD, validation, tables, efficiency, the gain sweep, the
recordings and the report. A second run in the same folder shows what
resuming costs when everything is already there.

Run: ``python benchmarks/run.py`` (or this file alone).
"""

from __future__ import annotations

import contextlib
import io
import os
import tempfile
import time
from pathlib import Path

from artic.validation.campaign.main import run_campaign


def main() -> dict[str, float]:
    jobs = os.cpu_count() or 1
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "out"
        t0 = time.perf_counter()
        with contextlib.redirect_stdout(io.StringIO()), \
                contextlib.redirect_stderr(io.StringIO()):
            run_campaign(out, jobs=jobs)
        first = time.perf_counter() - t0
        stages = _stages(out / "report.md")
        t0 = time.perf_counter()
        with contextlib.redirect_stdout(io.StringIO()), \
                contextlib.redirect_stderr(io.StringIO()):
            run_campaign(out, jobs=jobs)
        again = time.perf_counter() - t0
    print(f"Whole default campaign on {jobs} cores: {first:.0f} s from nothing "
          f"({first / 60:.1f} min), {again:.0f} s when resumed with everything in place")
    for name, wall in stages.items():
        print(f"  {name:<12} {wall:7.1f} s")
    return {"campaign_s": first, "resumed_s": again, **{f"stage_{k}": v for k, v in
                                                         stages.items()}}


def _stages(report: Path) -> dict[str, float]:
    """The stage table of a report."""
    out = {}
    lines = report.read_text().splitlines()
    start = lines.index("## Wall time by stage")
    for line in lines[start + 4:]:
        if not line.startswith("|"):
            break
        name, wall = (c.strip() for c in line.strip("|").split("|")[:2])
        out[name] = float(wall)
    return out


if __name__ == "__main__":
    main()
