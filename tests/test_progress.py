"""Progress lines and plant warnings: counts, time left, one line per run."""

from __future__ import annotations

import warnings

from artic.plant import PlantWarning
from artic.plant.tyre import TyreRangeWarning
from artic.validation.harness.plantnotes import collect, summary
from artic.validation.plumbing.progress import Counter, duration


def test_counter_counts_throttles_and_estimates():
    lines = []
    c = Counter(4, "validation, loaded", lines.append, every=3600.0)
    c.step("a")  # the first line comes at once
    c.step("b")  # throttled
    c.step("c", always=True)  # something to say
    c.step("d")  # the last
    assert [line.split(" - ")[0] for line in lines] == [
        "[1/4] validation, loaded: a", "[3/4] validation, loaded: c",
        "[4/4] validation, loaded: d"]
    assert " - " not in lines[0] and lines[-1].endswith("done")  # no estimate yet
    assert duration(45.2) == "45 s" and duration(185) == "3 min 05 s"
    assert duration(3720) == "1 h 02 min"


def test_the_first_estimate_leaves_out_the_start_up(monkeypatch):
    # The references stage's first estimate said about 1 h 04 min and settled near 10 min
    # (issue 46, item 19): its first item carried the start-up. 60 s of start-up, then one
    # item a second: with 96 left after the fourth item, about 96 s, not 96 x 15 s.
    from artic.validation.plumbing import progress

    now = [0.0]
    monkeypatch.setattr(progress.time, "perf_counter", lambda: now[0])
    lines = []
    c = Counter(100, "references", lines.append, every=0.0)
    for k in range(4):
        now[0] = 60.0 + k
        c.step(f"item {k}")
    assert [" - " in x for x in lines] == [False, False, False, True]
    assert lines[-1].endswith(" - about 1 min 36 s left"), lines[-1]


def test_plant_warnings_collected_as_one_line(recwarn):
    with collect() as notes:
        for t in (8.2, 8.21, 8.22):
            warnings.warn(f"t = {t:.2f} s: left-wheel angle -37.4 deg is beyond the linkage's "
                          "[-37.2, 51.4] deg; limited", PlantWarning, stacklevel=1)
        warnings.warn("x.tir at t = 9.00 s: tyre outside the file's valid range: front L: "
                      "alpha = -0.3 outside [-0.25, 0.25]", TyreRangeWarning, stacklevel=1)
        warnings.warn("something else", UserWarning, stacklevel=1)
    assert len(notes) == 4
    line = summary(notes)
    assert line == ("steering held at the linkage's range [-37.2, 51.4] deg from t = 8.20 s "
                    "(3 times); tyre outside its file's range (front L alpha) from t = 9.00 s")
    # Only the unrelated warning got through to the usual display.
    assert [str(w.message) for w in recwarn] == ["something else"]
    assert summary([]) == ""
