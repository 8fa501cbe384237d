"""The oracle vehicles: every model with the truth's own parameters, and what they split."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from artic.mjcf.vehicle import load_vehicle
from artic.validation.campaign import oracle
from artic.validation.runs.validate import validate_runs
from artic.validation.synthetic import yardtyres
from artic.validation.synthetic.generate import simulate_manoeuvre
from artic.validation.synthetic.sensors import SensorModel
from artic.validation.synthetic.testmatrix import MATRIX
from artic.validation.synthetic.truth import truth_configuration, truth_vehicle, write_truth_files
from artic.validation.synthetic.yardtruth import YardSetup

SEED, KIND = 0, "independent"


@pytest.mark.parametrize("load", ["unloaded", "loaded"])
def test_the_oracle_vehicle_carries_the_truths_drawn_parameters(tmp_path, load):
    truth = load_vehicle(write_truth_files(tmp_path, SEED, KIND)[load])  # as a campaign writes it
    preset = load_vehicle(f"gosar2022-{load}")
    v = oracle.oracle_vehicle(load, SEED, KIND, tmp_path / f"oracle-{load}.toml")
    for k in ("m1", "J1", "a1", "b1", "h1", "L1c", "m2", "J2", "a2", "h2", "L2"):
        assert getattr(v, k) == pytest.approx(getattr(truth, k), rel=1e-12), k
    # The draws moved the body off the preset (else the test would prove nothing).
    assert v.m1 != pytest.approx(preset.m1, rel=1e-6) and v.a2 != pytest.approx(preset.a2,
                                                                                 rel=1e-6)
    np.testing.assert_allclose(v.sensor1, truth.sensor1, rtol=0, atol=1e-12)
    gear = truth.steering_for("mbd")
    for m in ("kin", "stm", "mbd"):
        s = v.steering_for(m)
        assert s.i_s == pytest.approx(gear.i_s, rel=1e-12)
        assert s.delta_h_offset == pytest.approx(gear.delta_h_offset, rel=1e-12)
    assert v.steering_for("kin").q == preset.steering_for("kin").q  # the map's own asymmetry


def test_the_equivalent_stiffness_is_the_tmeasy_initial_slope_at_the_static_loads():
    cfg = truth_configuration(SEED, KIND)
    setup = YardSetup.of(cfg)
    v = truth_vehicle("loaded", cfg, SEED)
    # One tyre by hand: at the nominal load TMeasy's slope is dfy0_1, at twice it dfy0_2.
    t = yardtyres.yard_tyre("315/80R22.5", False, setup.pressure, setup.friction,
                            setup.cornering)
    assert oracle.tmeasy_cornering(t, t.fzn) == pytest.approx(t.dfy0_1, rel=1e-12)
    assert oracle.tmeasy_cornering(t, 2.0 * t.fzn) == pytest.approx(t.dfy0_2, rel=1e-12)
    assert oracle.tmeasy_cornering(t, 0.0) == 0.0
    c = oracle.truth_cornering(v, setup)
    f = oracle.equivalent_f(v, setup)
    assert f * v.static_loads.sum() == pytest.approx(c.sum(), rel=1e-12)
    # A truck tyre's cornering stiffness is some 5-10 times its load per radian.
    assert 4.0 < f < 10.0
    ov = oracle.oracle_vehicle("loaded", SEED, KIND)
    assert ov.f == pytest.approx(f, rel=1e-12)
    # The plant's tyres scaled to the same total at the same loads.
    from artic.plant.plant import scaled
    from artic.plant.tyre import TyreParams

    total = sum((4 if a.dual else 2) * float(scaled(TyreParams.from_tir(ov.tyre_file_for(a)),
                                                    ov.tyre_scaling).cornering_stiffness(
        fz / (4 if a.dual else 2))) for a, fz in zip(ov.axles, ov.static_loads, strict=True))
    assert total == pytest.approx(c.sum(), rel=1e-9)


def test_the_oracle_kin_on_a_noise_free_kinematic_log_is_closer_to_the_floor():
    # A constant steer at 5 km/h, measured with ideal sensors: KIN's kinematic case.
    m = next(m for m in MATRIX if m.name == "04-constant-steer-unloaded-360deg-5kph-left")
    log = simulate_manoeuvre(m, SEED, SensorModel.ideal())
    cfg = truth_configuration(SEED, KIND)
    floor = validate_runs([log], lambda lg: truth_vehicle(lg.meta["load"], cfg, SEED,
                                                          lg.meta.get("slope")), ["floor"])
    preset = validate_runs([log], load_vehicle("gosar2022-unloaded"), ["kin"])
    mine = validate_runs([log], oracle.oracle_vehicle("unloaded", SEED, KIND), ["kin"])
    for c in ("eps_p", "eps_gamma", "eps_a"):
        gap_oracle = float(mine[c].iloc[0] - floor[c].iloc[0])
        gap_preset = float(preset[c].iloc[0] - floor[c].iloc[0])
        # Above the floor (KIN's form costs something), and closer than the preset.
        assert 0.0 < gap_oracle < gap_preset, c


def _rows(values: dict[str, np.ndarray]) -> pd.DataFrame:
    return pd.DataFrame([{"log": f"{i:02d}", "model": m, "direction": "reverse",
                          "manoeuvre": "docking", "status": "ok", "eps_a": 0.0, "eps_v": 0.0,
                          "J_steer": x, "eps_n": x} for m, v in values.items()
                         for i, x in enumerate(v)])


def test_form_and_parameters_add_up_to_the_excess_over_the_floor():
    rng = np.random.default_rng(1)
    floor = rng.normal(10.0, 2.0, 12)
    form, params = rng.normal(5.0, 1.0, 12), rng.normal(-2.0, 1.0, 12)
    metrics = _rows({"kin": floor + form + params, "kin-oracle": floor + form, "floor": floor})
    split = oracle.split(metrics, "reverse")
    assert list(split.index) == ["kin form", "kin parameters"]
    assert split.loc["kin form", "J_steer"] == pytest.approx(form.mean(), rel=1e-12)
    assert split.loc["kin parameters", "J_steer"] == pytest.approx(params.mean(), rel=1e-12)
    pairs = oracle.form_pairs(metrics, "reverse")
    assert set(pairs["a"]) | set(pairs["b"]) == {"kin-oracle", "floor"}  # no tuned row
    row = pairs[pairs["criterion"] == "J_steer"].iloc[0]
    assert row["finding"] and math.isfinite(row["p_adj"])
