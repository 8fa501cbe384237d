"""Path distance: exact, and bounded in work and memory whatever one sample does.

No timing here (benchmarks/bench_pathdist_long.py times a 1 h log): the work
is counted as tree-node visits, which the module returns, and the memory is
the tree's size; both are deterministic.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from artic.validation.cli.commands import main
from artic.validation.criteria.pathdist import LEAF, _build, distance_to_polyline
from artic.validation.logs.runfile import write_run
from tests.hostile_logs import slalom


def brute_force(points: np.ndarray, path: np.ndarray) -> np.ndarray:
    """Every point against every segment, in complex numbers (independent of pathdist)."""
    z = points[:, 0] + 1j * points[:, 1]
    p = path[:, 0] + 1j * path[:, 1]
    a, e = p[:-1][None, :], (p[1:] - p[:-1])[None, :]
    s = np.where(e == 0, 0.0, np.clip(np.real((z[:, None] - a) / np.where(e == 0, 1, e)), 0, 1))
    return np.abs(z[:, None] - (a + s * e)).min(axis=1)


def yard_path(n: int, step_at: int | None = None, step: float = 500.0):
    """A slalom-like path at 100 Hz, model points 0.3 m beside it; optionally a position step."""
    t = np.arange(n) * 0.01
    path = np.column_stack([1.5 * t, 3.0 * np.sin(t / 4.0)])
    points = path + [0.0, 0.3]
    if step_at is not None:  # sideways, so the stepped part overlaps nothing
        path = path.copy()
        path[step_at:, 1] += step
    return points, path


def test_exact_with_a_500_m_step():
    points, path = yard_path(3000, step_at=1500)
    sub = points[::7]
    np.testing.assert_allclose(distance_to_polyline(sub, path), brute_force(sub, path),
                               rtol=0, atol=1e-9)


@pytest.mark.parametrize("n", [4000, 16000, 64000])
def test_a_500_m_step_adds_at_most_log_m_work_per_point(n):
    # The old search made every point examine the whole path once one segment was
    # 500 m long (quadratic work). Here the step adds at most a few visits per level
    # of the tree for each point: the grown boxes are the step's leaves' ancestors.
    points, clean = yard_path(n)
    _, stepped = yard_path(n, step_at=n // 2)
    d0, w0 = distance_to_polyline(points, clean, return_work=True)
    d1, w1 = distance_to_polyline(points, stepped, return_work=True)
    levels = math.log2(n / LEAF) + 2
    assert w1 <= w0 + 4 * n * levels, (w0, w1)
    assert w1 < 0.01 * n * n  # far from examining every segment for every point
    k = slice(None, None, n // 40)
    np.testing.assert_allclose(d0[k], brute_force(points[k], clean), rtol=0, atol=1e-9)
    np.testing.assert_allclose(d1[k], brute_force(points[k], stepped), rtol=0, atol=1e-9)
    assert d0.max() <= 0.3 + 1e-12  # never farther than the 0.3 m offset


def test_work_is_n_log_n():
    # O(N log M) node visits, step or no step: the per-point work grows by about one
    # visit per doubling of the log (one more tree level), never with the log's length.
    for n in (20000, 40000, 80000):
        points, path = yard_path(n, step_at=n // 3)
        work = distance_to_polyline(points, path, return_work=True)[1]
        assert work <= 2.0 * n * math.log2(n), (n, work / n)


def test_memory_is_linear_in_the_path():
    # The tree holds at most 2 * (next power of two of M / LEAF) boxes, whatever the
    # geometry; no array of candidates per point exists any more.
    _, path = yard_path(100_001, step_at=50_000, step=1e6)
    a, b = path[:-1], path[1:]
    lo, hi, size = _build(a[:, 0].copy(), a[:, 1].copy(), b[:, 0].copy(), b[:, 1].copy())
    assert lo.shape == hi.shape == (2 * size, 2)
    assert 2 * size <= 4 * math.ceil(len(a) / LEAF)


def test_non_finite_points_and_degenerate_paths():
    d = distance_to_polyline(np.array([[np.nan, 0.0], [3.0, 4.0]]), np.zeros((3, 2)))
    assert math.isnan(d[0]) and d[1] == pytest.approx(5.0)
    with pytest.raises(ValueError, match="non-finite"):
        distance_to_polyline(np.zeros((1, 2)), np.array([[0.0, 0.0], [np.inf, 1.0]]))


def test_validating_a_log_with_a_500_m_step(tmp_path, capsys):
    # The 40 s log of the review (3 GB and 14 s before): refused by the jump check,
    # validated when the user accepts it, and the distance is the step's.
    run = slalom()
    f = run.frame
    f.loc[1500:, ["y_1", "y_2"]] += 500.0
    p = write_run(run, tmp_path / "step.parquet")
    out = tmp_path / "val"
    assert main(["validate", str(p), "--models", "kin", "--out-dir", str(out)]) == 2
    assert "position jumps 500 m" in capsys.readouterr().err
    assert main(["validate", str(p), "--models", "kin", "--out-dir", str(out),
                 "--accept", "jump"]) == 0
    stepped = pd.read_csv(out / "metrics.csv").loc[0]
    # Against the same log without the step: the step shows, as a finite number.
    clean = tmp_path / "clean"
    write_run(slalom(), clean / "step.parquet")
    assert main(["validate", str(clean / "step.parquet"), "--models", "kin", "--out-dir",
                 str(tmp_path / "val-clean")]) == 0
    base = pd.read_csv(tmp_path / "val-clean" / "metrics.csv").loc[0]
    assert stepped.status == base.status == "ok"
    assert math.isfinite(stepped.eps_y1) and stepped.eps_y1 > 10.0 * base.eps_y1
