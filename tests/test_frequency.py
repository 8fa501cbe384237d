"""The frequency response's estimator, on systems whose transfer function is known."""

from __future__ import annotations

import cmath
import math

import numpy as np
import pandas as pd
import pytest

from artic.mjcf.vehicle import load_vehicle
from artic.reduced.control import KIN
from artic.validation.harness.simulate import simulate
from artic.validation.models import build, steering_for
from artic.validation.review.frequency import CENTRES, compare, departure, response
from artic.validation.synthetic.manoeuvres import make_profile
from artic.validation.synthetic.testmatrix import SWEEP

DT = 0.01


def _sweep() -> tuple[np.ndarray, np.ndarray]:
    p = make_profile("swept-sine", amplitude_deg=SWEEP[0], speed_kph=SWEEP[1])
    return p.t, p.delta_h


def test_a_first_order_system_gives_its_gain_and_phase():
    # y' = (K u - y) / tau, held input, stepped exactly: y[k+1] = a y[k] + K (1 - a) u[k],
    # a = exp(-dt / tau); its transfer function is K (1 - a) z^-1 / (1 - a z^-1),
    # z = exp(j 2 pi f dt). Over a third octave the true gain of a first-order lag at
    # its corner changes by 12 %; the band average, weighted by the input's power, sits
    # within 1 % and 1 deg of the centre's value (0.5 % and 0.6 deg measured).
    t, u = _sweep()
    K, tau = 2.0, 1.0
    a = math.exp(-DT / tau)
    y = np.zeros_like(u)
    for k in range(u.size - 1):
        y[k + 1] = a * y[k] + K * (1.0 - a) * u[k]
    h = response(t, u, y)
    for c, est in zip(CENTRES, h, strict=True):
        z = cmath.exp(2j * math.pi * c * DT)
        exact = K * (1.0 - a) / (z - a)
        assert abs(est) / abs(exact) == pytest.approx(1.0, abs=0.01), c
        assert math.degrees(cmath.phase(est / exact)) == pytest.approx(0.0, abs=1.0), c
    # and the lag: the corner 1 / (2 pi tau) = 0.16 Hz lies between 45 deg above and below
    assert math.degrees(cmath.phase(h[4])) == pytest.approx(-45.0, abs=2.0)  # 0.159 Hz


def test_kin_yaw_rate_gain_is_the_kinematic_limit():
    # KIN's tractor turns on its wheelbase: r_1 = u1 tan(delta) / L1, delta = (d - q d^2) / i_s.
    # Per radian of steering wheel the gain is u1 / (L1 i_s) at every frequency, phase 0;
    # tan adds delta^2 / 3 = 0.2 % at the sweep's 4.4 deg, the quadratic q d^2 puts up to
    # q A / 2 = 0.8 % into a harmonic: 2 % covers both.
    vehicle = load_vehicle("gosar2022-loaded")
    model = KIN(vehicle, wheelbase="paper")
    p = make_profile("swept-sine", amplitude_deg=SWEEP[0], speed_kph=SWEEP[1])
    run = simulate(model, vehicle, p)
    i_s = steering_for(vehicle, model).i_s
    expected = SWEEP[1] / 3.6 / (model.L1 * i_s)
    h = response(run.frame["t"].to_numpy(), run.frame["delta_h"].to_numpy(),
                 run.frame["r_1"].to_numpy())
    assert np.abs(h) == pytest.approx(np.full(h.size, expected), rel=0.02)
    assert np.degrees(np.angle(h)) == pytest.approx(np.zeros(h.size), abs=1.0)


def test_the_single_track_model_tends_to_the_kinematic_gain():
    # At 10 km/h the STM's tyres slip little: at the lowest band (0.063 Hz) its yaw-rate
    # gain is the kinematic u1 / (L1 i_s) of the drive axle's wheelbase, within the 3 %
    # the semitrailer's scrub and the tractor's understeer change a steady low-speed turn
    # of the loaded truck (1 % measured), and it lags by a few degrees at most.
    vehicle = load_vehicle("gosar2022-loaded")
    model = build("stm", vehicle)
    p = make_profile("swept-sine", amplitude_deg=SWEEP[0], speed_kph=SWEEP[1])
    run = simulate(model, vehicle, p)
    i_s = steering_for(vehicle, model).i_s
    expected = SWEEP[1] / 3.6 / (vehicle.L1 * i_s)
    h = response(run.frame["t"].to_numpy(), run.frame["delta_h"].to_numpy(),
                 run.frame["r_1"].to_numpy())
    assert abs(h[0]) == pytest.approx(expected, rel=0.03)
    assert -5.0 < math.degrees(cmath.phase(h[0])) <= 0.5


def _frame(t, u, r):
    return pd.DataFrame({"t": t, "delta_h": u, "r_1": r, "r_2": 0.5 * r, "gamma": 2.0 * r})


class _Run:
    def __init__(self, frame):
        self.frame = frame


def test_compare_and_departure():
    # a model whose every output is 1.2 times the truth's errs by 20 % in gain in every
    # band and not in phase: it departs from the first band on; the truth itself never
    t, u = _sweep()
    r = np.convolve(u, np.full(50, 0.02), mode="full")[: u.size]  # any causal response
    truth = _Run(_frame(t, u, r))
    table = compare(truth, {"same": _Run(_frame(t, u, r)), "big": _Run(_frame(t, u, 1.2 * r))})
    big = table[table["model"] == "big"]
    assert big["gain_error"].to_numpy() == pytest.approx(np.full(len(big), 0.2), abs=1e-9)
    assert big["phase_error"].abs().max() < 1e-6
    dep = departure(table)
    assert dep.loc["big"].to_list() == [CENTRES[0]] * 3
    assert dep.loc["same"].isna().all()


@pytest.mark.slow
def test_the_study_drives_the_truth_and_each_model_on_the_sweep():
    # seed 0's truth and KIN: every signal in every band, and KIN's articulation gain
    # departs from the truth's somewhere in the sweep (its equivalent wheelbase, untuned)
    from artic.validation.review.frequencystudy import frequency_study

    table, dep = frequency_study(0, models=("kin",))
    assert len(table) == 3 * len(CENTRES) and set(table["model"]) == {"kin"}
    assert np.isfinite(table[["gain", "gain_truth", "phase", "phase_truth"]].to_numpy()).all()
    assert list(dep.index) == ["kin"] and np.isfinite(dep.loc["kin", "gamma"])
