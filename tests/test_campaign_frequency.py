"""The campaign's frequency tables: per truck from the swept sine's run files, and over trucks."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from artic.validation.campaign import frequency
from artic.validation.logs.runfile import Run, write_run
from artic.validation.review.frequency import CENTRES
from artic.validation.synthetic.manoeuvres import make_profile
from artic.validation.synthetic.testmatrix import SWEEP
from tests.helpers import straight_log

NAME = "62-swept-sine-loaded-90deg-10kph-left"


def _log(scale: float = 1.0) -> Run:
    """A swept-sine log whose outputs lag its steering through first-order lags."""
    p = make_profile("swept-sine", amplitude_deg=SWEEP[0], speed_kph=SWEEP[1])
    base = straight_log(n=p.t.size, u=SWEEP[1] / 3.6)
    f = base.frame
    f["delta_h"] = p.delta_h
    for name, tau, gain in (("r_1", 0.1, 0.035), ("gamma", 3.0, 0.1)):
        a = math.exp(-0.01 / tau)
        y = np.zeros(p.t.size)
        for k in range(p.t.size - 1):
            y[k + 1] = a * y[k] + scale * gain * (1 - a) * p.delta_h[k]
        f[name] = y
    # the headings and r_2 that agree with them (the run files' consistency checks)
    f["psi_1"] = np.concatenate(([0.0], np.cumsum(0.5 * (f["r_1"].to_numpy()[1:]
                                                        + f["r_1"].to_numpy()[:-1]) * 0.01)))
    f["psi_2"] = f["psi_1"] - f["gamma"]
    f["r_2"] = np.gradient(f["psi_2"].to_numpy(), 0.01)
    return Run(f, {"name": NAME, "manoeuvre": "swept-sine", "load": "loaded"})


@pytest.fixture(scope="module")
def truck(tmp_path_factory):
    out = tmp_path_factory.mktemp("seed-0")
    log = _log()
    (out / "runs").mkdir()
    for model, run in (("same", log), ("big", _log(1.25))):
        write_run(Run(run.frame.copy(), {"name": f"{NAME}.{model}"}),
                  out / "runs" / f"{NAME}.{model}.parquet")
    # a reference that keeps no samples is passed over
    (out / "runs" / f"{NAME}.floor.parquet").write_bytes(b"")
    return out, log


def test_one_truck_tabulates_every_band_and_the_departure(truck):
    out, log = truck
    paths = frequency.write(out, [log, straight_log()])  # the straight log is no sweep
    assert set(paths) == {frequency.STEM, frequency.DEPARTURE}
    table = pd.read_csv(out / f"{frequency.STEM}.csv", index_col=0)
    assert set(table["model"]) == {"same", "big"}
    big = table[table["model"] == "big"]
    # 1.25 times every output: a gain error of 0.25 in every band, no phase error
    assert big["gain_error"].to_numpy() == pytest.approx(np.full(len(big), 0.25), abs=1e-9)
    assert big["phase_error"].abs().max() < 1e-6
    text = (out / f"{frequency.DEPARTURE}.md").read_text()
    assert f"{CENTRES[0]:.3g}" in text


def test_no_sweep_no_tables(tmp_path):
    assert frequency.write(tmp_path, [straight_log()]) == {}
    assert frequency.write_pooled(tmp_path, [tmp_path / "seed-0"]) == {}


def test_trucks_pool_into_means_with_intervals(truck, tmp_path):
    out, _ = truck
    frequency.write(out, [truck[1]])
    paths = frequency.write_pooled(tmp_path, [out, out])  # the same truck twice
    pooled = pd.read_csv(paths[frequency.STEM], index_col=0)
    big = pooled[pooled["model"] == "big"]
    assert (big["n"] == 2).all()
    assert big["gain_error"].to_numpy() == pytest.approx(np.full(len(big), 0.25), abs=1e-9)
    dep = pd.read_csv(paths[frequency.DEPARTURE], index_col=0)
    assert dep.loc["big"].to_numpy() == pytest.approx([CENTRES[0]] * 3, rel=1e-6)  # %.6g
    assert dep.loc["same"].isna().all()
