"""Tuning: the objective is the criteria, and a model tuned on its own output finds its truth."""

from __future__ import annotations

import math

import numpy as np
import pytest

from artic.mjcf.writer import fitted_changes, updated, write_vehicle
from artic.reduced import KIN, STM
from artic.validation.campaign.tuning import Objective, apply, bounds_for, tune_model
from artic.validation.criteria.metrics import run_metrics
from artic.validation.harness.loop import run_closed_loop
from artic.validation.harness.simulate import simulate
from artic.validation.synthetic.manoeuvres import make_profile
from tests.helpers import as_log

TRUTH = {"stm": {"f": 7.4, "i_s": 22.3, "q": 0.006, "delta_h_offset": 0.061},
         "kin": {"i_s": 19.8, "q": 0.012, "delta_h_offset": -0.03}}


def own_logs(vehicle, model: str, truth: dict) -> list:
    """Constant steers of the model itself at its truth parameters: four, left and right."""
    v = apply(vehicle, model, truth)
    s = v.steering_for(model)
    cls = {"kin": KIN, "stm": STM}[model]
    logs = []
    for amp in (200.0, 500.0):
        for side in ("left", "right"):
            p = make_profile("constant-steer", amplitude_deg=amp, speed_kph=8.0, side=side,
                             duration=15.0, delta_h_offset=s.delta_h_offset)
            logs.append(as_log(simulate(cls(v), v, p), f"{model}-{amp:.0f}-{side}"))
    return logs


@pytest.mark.parametrize("model", ["kin", "stm"])
def test_tuning_recovers_its_own_truth(unloaded, model):
    # Noise-free logs of the model itself: the least-squares optimum is the
    # truth exactly, so the fit must land on it to the solver's tolerance
    # (xtol 1e-6 of each bound's span: 1e-5 in i_s, 5e-7 rad in the offset).
    truth = TRUTH[model]
    logs = own_logs(unloaded, model, truth)
    fit = tune_model(model, unloaded, logs)
    for k, v in truth.items():
        assert fit.fitted[k] == pytest.approx(v, rel=1e-3, abs=1e-4), k
    assert fit.eps_n_before > 5.0 > 0.05 > fit.eps_n_after
    assert fit.cost_after < 1e-6 * fit.cost_before
    assert not fit.at_bound


def test_objective_is_the_criterion(unloaded):
    # The residuals' norms per signal are eps / mean_abs, so their sum is eps_n
    # exactly as the metrics module computes it.
    logs = own_logs(unloaded, "kin", TRUTH["kin"])
    obj = Objective("kin", unloaded, logs)
    x = np.array([b.nominal for b in obj.bounds])
    v = obj.vehicle_at(x)
    direct = np.mean([run_metrics(log.frame, run_closed_loop(KIN(v), log, v).frame)
                      ["eps_n"] for log in logs])
    assert obj.eps_n(x) == pytest.approx(direct, rel=1e-9)


def test_bounds_keep_the_map_monotonic(unloaded):
    logs = own_logs(unloaded, "kin", TRUTH["kin"])
    b = {x.name: x for x in bounds_for("kin", unloaded, logs)}
    peak = max(np.abs(log.frame["delta_h"]).max() for log in logs)
    # 90 % of the fold 1/(2q) lies beyond the largest angle plus the largest offset.
    assert 0.9 / (2 * b["q"].hi) >= peak + math.radians(15) - 1e-12
    assert b["i_s"].lo == pytest.approx(0.75 * 20.5) and b["i_s"].hi == pytest.approx(1.25 * 20.5)


def test_tuned_file_round_trips(unloaded, tmp_path):
    fitted = {"stm": {"f": 7.5, "i_s": 21.9, "q": 0.008, "delta_h_offset": 0.07},
              "kin": {"i_s": 20.1, "q": 0.009, "delta_h_offset": 0.08}}
    data = updated("gosar2022-unloaded", fitted_changes(unloaded, fitted), "test fit",
                   name="tuned")
    v = write_vehicle(data, tmp_path / "sub" / "tuned.toml")
    assert v.name == "tuned" and v.f == 7.5 and v.sources[-1] == "test fit"
    assert v.steering_for("stm").i_s == 21.9 and v.steering_for("kin").q == 0.009
    assert v.steering_for("mbd") == unloaded.steering_for("mbd")
    assert v.tyre_file == unloaded.tyre_file  # still found, from another folder
    assert list((tmp_path / "sub").iterdir()) == [tmp_path / "sub" / "tuned.toml"]


def test_the_parallel_jacobian_is_least_squares_own_difference(unloaded):
    # The plant's first Jacobian runs its columns at once; its steps must be those
    # of least_squares' two-point scheme (rel_step DIFF_STEP, bounds [0, 1], a
    # backward step at the upper bound). Same residual evaluations, so the
    # columns agree to rounding.
    from scipy.optimize._numdiff import approx_derivative

    from artic.validation.campaign.tuning import DIFF_STEP, ParallelJacobian

    logs = own_logs(unloaded, "kin", TRUTH["kin"])[:2]
    obj = Objective("kin", unloaded, logs)
    lo = np.array([b.lo for b in obj.bounds])
    span = np.array([b.hi - b.lo for b in obj.bounds])
    for z in (np.array([0.4, 0.3, 0.55]), np.array([0.5, 0.9995, 0.2])):  # the 2nd at q's bound
        jac = ParallelJacobian(obj, lo, span)
        f0 = jac.fun(z)
        before = obj.evaluations
        ours = jac(z)
        assert obj.evaluations - before == z.size  # the point itself was not run again
        ref = approx_derivative(jac.fun, z, method="2-point", rel_step=DIFF_STEP,
                                bounds=(0.0, 1.0), f0=f0)
        np.testing.assert_allclose(ours, ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())


def test_broyden_updates_meet_the_secant_condition_without_a_run(unloaded):
    # After the first Jacobian, each accepted point updates it by rank one so that
    # J_new (z_new - z_old) = f_new - f_old exactly (to rounding), at no plant run.
    from artic.validation.campaign.tuning import ParallelJacobian

    logs = own_logs(unloaded, "kin", TRUTH["kin"])[:2]
    obj = Objective("kin", unloaded, logs)
    lo = np.array([b.lo for b in obj.bounds])
    span = np.array([b.hi - b.lo for b in obj.bounds])
    jac = ParallelJacobian(obj, lo, span)
    z1, z2 = np.array([0.4, 0.3, 0.55]), np.array([0.42, 0.29, 0.56])
    f1 = jac.fun(z1)
    J1 = jac(z1)
    f2 = jac.fun(z2)
    before = obj.evaluations
    J2 = jac(z2)
    assert obj.evaluations == before
    np.testing.assert_allclose(J2 @ (z2 - z1), f2 - f1, atol=1e-12 * np.abs(f2 - f1).max())
    # Orthogonal to the step, the old Jacobian is kept.
    w = np.cross(z2 - z1, [1.0, 0.0, 0.0])
    np.testing.assert_allclose(J2 @ w, J1 @ w, atol=1e-12 * np.abs(J1 @ w).max())


def test_a_last_step_within_xtol_is_not_run_and_changes_the_fit_less_than_xtol(unloaded):
    # The plant's fit does not run a trial step shorter than least_squares' own
    # xtol test, which would end the fit after it whatever its outcome: the fit
    # ends one evaluation earlier, at the current point, less than that step
    # from where least_squares would have ended. KIN stands in for the plant
    # (the same objective and Jacobian, 100 times cheaper), from a start the
    # plant's way: offset and ratio near the truth, q at its bound.
    from scipy.optimize import least_squares

    from artic.validation.campaign.tuning import (
        TOLERANCES,
        ParallelJacobian,
        WithinTolerance,
        start_values,
    )

    logs = own_logs(unloaded, "kin", TRUTH["kin"])
    xtol, ftol = TOLERANCES["plant"]
    ends = {}
    for skip in (False, True):
        obj = Objective("kin", unloaded, logs)
        lo = np.array([b.lo for b in obj.bounds])
        span = np.array([b.hi - b.lo for b in obj.bounds])
        z0 = (start_values(obj.bounds, {"i_s": 20.3, "delta_h_offset": -0.02}) - lo) / span
        jac = ParallelJacobian(obj, lo, span, xtol if skip else None)
        points = []  # where least_squares stood: each point it asked the Jacobian at

        def jacobian(z, *_, jac=jac, points=points):
            points.append(np.array(z))
            return jac(z)

        jac.fun(z0)
        try:
            sol = least_squares(jac.fun, z0, jac=jacobian, bounds=(0.0, 1.0), method="trf",
                                x_scale=1.0, xtol=xtol, ftol=ftol, max_nfev=40)
            ends[skip] = (sol.x, sol.status, obj.evaluations, points)
        except WithinTolerance as done:
            ends[skip] = (done.z, "within xtol", obj.evaluations, points)
    (z_full, status, n_full, path), (z_skip, why, n_skip, path_skip) = ends[False], ends[True]
    assert status == 3 and why == "within xtol"  # the full fit ended on its step length
    assert n_skip == n_full - 1  # exactly its last evaluation spared
    # The same path up to there; the shortened fit ends where the full one stood
    # before its last step (or at its end, had that step been refused).
    assert len(path_skip) in (len(path) - 1, len(path))
    for a, b in zip(path_skip, path, strict=False):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(z_skip, path_skip[-1])
    assert np.linalg.norm(z_skip - z_full) < xtol * (xtol + np.linalg.norm(z_skip))


def test_the_plant_starts_from_the_stm_steering_column():
    from artic.validation.campaign.main import start_from
    from artic.validation.campaign.tuning import Bound, start_values

    fitted = {"stm": {"f": 9.0, "i_s": 22.3, "q": 0.007, "delta_h_offset": 0.1}}
    assert start_from("mbd", fitted) == {"i_s": 22.3, "delta_h_offset": 0.1}  # not q, not f
    assert start_from("kin", fitted) is None and start_from("mbd", {}) is None
    bounds = [Bound("i_s", 20.0, 15.0, 25.0), Bound("q", 0.0, 0.0, 0.04),
              Bound("delta_h_offset", 0.0, -0.26, 0.26)]
    x = start_values(bounds, {"i_s": 30.0, "delta_h_offset": 0.1})
    # i_s is held inside its bound with room for a forward step; q keeps its nominal
    # value, 0, but a hair above its lower bound, where least_squares leaves it.
    assert x[0] == pytest.approx(25.0 - 1e-3 * 10.0) and x[1] == 0.04e-6 and x[2] == 0.1


@pytest.mark.slow
def test_the_plant_fit_matches_full_differences_from_nominal(unloaded):
    # The campaign's plant fit (STM start, one difference Jacobian, Broyden's
    # updates, TOLERANCES["plant"]) against least_squares' own differences at
    # every step from the nominal values with KIN's and STM's tolerances: the
    # same optimum within the plant's xtol (1e-4 of each span: 1e-3 in i_s,
    # 5e-5 rad in the offset) times the flat valley's amplification; 2e-4
    # relative in i_s and 3.5e-4 rad (0.02 deg) in the offset.
    from artic.validation.campaign.tuning import full_difference_fit

    logs = own_logs(unloaded, "stm", TRUTH["stm"])[:2]
    obj = Objective("mbd", unloaded, logs, jobs=2)
    x_ref, cost_ref = full_difference_fit(obj)
    full = obj.evaluations
    fit = tune_model("mbd", unloaded, logs, jobs=2,
                     start={"i_s": TRUTH["stm"]["i_s"],
                            "delta_h_offset": TRUTH["stm"]["delta_h_offset"]})
    assert fit.fitted["i_s"] == pytest.approx(x_ref["i_s"], rel=2e-4)
    assert fit.fitted["delta_h_offset"] == pytest.approx(x_ref["delta_h_offset"], abs=3.5e-4)
    assert fit.cost_after == pytest.approx(cost_ref, rel=1e-3)
    assert fit.evaluations < full / 2


def test_the_quasi_newton_fit_reaches_least_squares_optimum_with_large_residuals(unloaded):
    # The STM's fit runs L-BFGS-B on the sum of squares (it tunes f); the
    # reference is least_squares' trust-region Gauss-Newton with its own
    # differences from the nominal values (full_difference_fit). On logs the
    # STM cannot fit exactly (its own runs, the yaw rate read 3 % high, a
    # 2 cm/s lateral-velocity bias on the semitrailer and seeded noise:
    # eps_n stays at several %, the large-residual case where Gauss-Newton's
    # J^T J misses curvature), both must find the same minimum: the cost
    # within 1e-6 relative of the lower one (both stop on ftol-sized changes,
    # 1e-10 absolute against a cost near 1e-2), and the parameters within
    # 2e-3 relative, the width of the flat valley along f that the reference
    # crawls through before its ftol stops it.
    from artic.validation.campaign.tuning import full_difference_fit

    rng = np.random.default_rng(7)
    logs = own_logs(unloaded, "stm", TRUTH["stm"])
    for log in logs:
        f = log.frame
        f["r_1"] = 1.03 * f["r_1"] + rng.normal(0.0, 2e-3, len(f))
        f["v_y_2"] = f["v_y_2"] + 0.02 + rng.normal(0.0, 5e-3, len(f))
    ref_obj = Objective("stm", unloaded, logs)
    x_ref, cost_ref = full_difference_fit(ref_obj)
    fit = tune_model("stm", unloaded, logs)
    assert fit.eps_n_after > 1.0  # a large-residual problem indeed
    assert fit.cost_after <= cost_ref * (1.0 + 1e-6)
    assert cost_ref <= fit.cost_after * (1.0 + 1e-6)
    for k, v in x_ref.items():
        assert fit.fitted[k] == pytest.approx(v, rel=2e-3, abs=1e-5), k
