"""The feedback gain sweep and its stability bound."""

from __future__ import annotations

import pytest

from artic.validation.campaign.gainsweep import (
    gain_sweep,
    plot_gain_sweep,
    stability_bound,
    sweep_table,
)
from conftest import straight_log


def test_bound_is_eq7(unloaded):
    assert stability_bound(unloaded) == pytest.approx(unloaded.L1 / (unloaded.L2 - unloaded.L1c))


def test_sweep_separates_at_the_bound(unloaded, tmp_path):
    # Straight reversing from 0.1 rad of articulation: below K_min the model's
    # articulation runs away from the log's and eps_n grows; above it the
    # feedback pulls it back. Far above, the feedback costs steering effort.
    k_min = stability_bound(unloaded)
    logs = {"unloaded": (unloaded, [straight_log(n=3000, u=-0.8, gamma0=0.1)])}
    sweep = gain_sweep(logs, ["kin"], gains=(0.5 * k_min, 2 * k_min, 8.0))
    by_k = sweep.set_index("K")
    err = by_k["eps_a"]
    assert err[0.5 * k_min] > 3 * err[2 * k_min]
    assert sweep.attrs["K_min"] == pytest.approx(k_min)
    table = sweep_table(sweep)
    assert list(table["stable"]) == ["no", "bound", "yes", "yes"]
    plot_gain_sweep(sweep, tmp_path / "sweep.png", 3.0)
    assert (tmp_path / "sweep.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
