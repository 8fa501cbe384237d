"""The exports' CSV text is pandas' ``to_csv(index=False)``, byte for byte."""

from __future__ import annotations

import numpy as np
import pandas as pd

from artic.validation.logs.csvtext import csv_text


def _values(rng: np.random.Generator, n: int) -> np.ndarray:
    """Floats of every kind the exports hold and more: rounded like their columns,
    across 40 orders of magnitude, from random bits, and the edges of the format."""
    scale = 10.0 ** rng.uniform(-20, 20, n)
    edges = [0.0, -0.0, 1.0, -1.0, 1e16, 1e16 - 2, 9999999999999998.0, 1e-4, 9.999e-5, 1e-5,
             0.1, 1 / 3, 5e-324, 2.2250738585072014e-308, 1.7976931348623157e308, np.inf,
             -np.inf, 51.45, 5.39, 359.99999, 123.45678901]
    bits = rng.integers(0, 2 ** 63, n).view(np.float64)
    bits = bits[np.isfinite(bits)]
    return np.concatenate([edges, rng.normal(size=n) * scale, (rng.normal(size=n) * 90).round(5),
                           (51.45 + rng.normal(size=n) * 1e-3).round(10),
                           (np.arange(n) * 0.01).round(4), bits])


def test_float_tables_as_pandas_writes_them():
    rng = np.random.default_rng(7)
    v = _values(rng, 20_000)
    table = pd.DataFrame({"Time": v, "PosLat": rng.permutation(v), "AngRateZ": -v})
    assert csv_text(table) == table.to_csv(index=False)


def test_one_column_and_empty_tables():
    for table in (pd.DataFrame({"Time": [0.0, 0.01, -0.0]}),
                  pd.DataFrame({"Time": np.array([], dtype=float), "SWA": np.array([])}),
                  pd.DataFrame({"Time": np.array([], dtype=float)})):
        assert csv_text(table) == table.to_csv(index=False)


def test_what_pandas_writes_itself():
    """Missing values, other dtypes, names that need quoting, repeated names."""
    tables = [pd.DataFrame({"a": [1.0, np.nan], "b": [2.0, 3.0]}),
              pd.DataFrame({"a": [np.nan]}),
              pd.DataFrame({"a": [1, 2], "b": [0.5, 0.25]}),
              pd.DataFrame({"a,b": [1.0], 'q"': [2.0]}),
              pd.DataFrame([[1.0, 2.0]], columns=["a", "a"]),
              pd.DataFrame({"a": np.array([1.5, 2.5], dtype=np.float32)})]
    for table in tables:
        assert csv_text(table) == table.to_csv(index=False)
