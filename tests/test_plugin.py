"""artic's pytest plugin, as a user's test suite meets it (pytest's ``pytester``).

A user's test file that uses only the plugin's fixtures and assertions must
pass for a model that is right and fail, with the criteria table, for one
that is wrong; the session's logs are made once and read back after.
"""

from __future__ import annotations

import dataclasses
import json
import math
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from artic.validation import testing
from artic.validation.testing import assert_agree, assert_tracks, criteria_table
from tests.helpers import straight_log

pytest_plugins = ["pytester"]

USER_TESTS = """
import artic
from artic.validation.testing import assert_agree, assert_tracks


def kin(vehicle):
    \"\"\"The user's model: KIN, with its tractor wheelbase scaled by WHEELBASE.\"\"\"
    model = artic.KIN(vehicle)
    model.params = model.params._replace(L1=WHEELBASE * model.params.L1)
    return model


def test_tracks_the_logs(artic_vehicle, artic_logs):
    assert_tracks(kin(artic_vehicle), artic_logs, within={"eps_p": 4.0, "eps_a": 0.015})


def test_agrees_with_the_plant(artic_plant, artic_logs):
    assert_agree(artic_plant, kin, artic_logs, within={"eps_a": 0.01, "eps_p": 3.0})
"""


@pytest.fixture(scope="module")
def shared_cache(pytestconfig, tmp_path_factory):
    """A pytest cache folder the users' sessions share, so that they make the logs once."""
    cache = getattr(pytestconfig, "cache", None)  # None under -p no:cacheprovider
    return cache.mkdir("artic-pytester") if cache is not None else \
        tmp_path_factory.mktemp("artic-pytester")


# A user's pytest session in a process of its own: end to end, in the slow set (issue 42).
@pytest.mark.slow
def test_a_users_tests_pass_for_a_right_model_and_fail_with_the_table_for_a_wrong_one(
        pytester, shared_cache):
    # A fresh process, as a user's suite: the plugin comes from artic's
    # pytest11 entry point; the user's files use only its fixtures and
    # assertions. The wrong model is KIN with a tractor wheelbase 40 % too
    # long: it turns 1/1.4 as fast for the same steering (r_1 = u tan(delta)
    # / L1), a yaw-rate error of about 0.3 of the constant steer's 0.03
    # rad/s on each unit, and metres of drift over its 56 m.
    pytester.makeini(f"[pytest]\ncache_dir = {shared_cache}\n")
    pytester.makepyfile(test_right=USER_TESTS.replace("WHEELBASE", "1.0"),
                        test_wrong=USER_TESTS.replace("WHEELBASE", "1.4"))
    result = pytester.runpytest_subprocess("-q")
    result.assert_outcomes(passed=2, failed=2)
    # The table: every criterion of every manoeuvre with its value, limit and
    # verdict, and the progress term the check adds. Forward, the wrong KIN's
    # circle is metres off the measured one (eps_p), so the measured path is
    # metres from its path too (eps_cover, beyond a lane per unit). Reversing,
    # the harness's feedback holds even the wrong KIN.
    result.stdout.fnmatch_lines([
        "E*AssertionError: kin does not track the log(s) within the criteria (3 failure(s), "
        "K = 3):",
        "E*manoeuvre*criterion*value*limit*result",
        "E*00-constant-steer-unloaded-200deg-5kph-left*eps_p*m*4 m*FAIL",
        "E*eps_a*rad/s*0.015 rad/s*FAIL",
        "E*eps_cover*m*7 m (default)*FAIL",
        "E*28-ramp-steer-reverse-unloaded-30deg-6kph-right*eps_p*m*4 m*pass",
        "E*eps_a*rad/s*0.015 rad/s*pass",
        "E*eps_cover*m*7 m (default)*pass",
    ])
    result.stdout.fnmatch_lines([
        "E*AssertionError: kin does not agree with mbd within the criteria*",
        "E*manoeuvre*criterion*value*limit*result",
        "E*00-constant-steer-unloaded-200deg-5kph-left*eps_a*rad/s*0.01 rad/s*FAIL",
    ])
    result.stdout.fnmatch_lines(["FAILED test_wrong.py::test_tracks_the_logs*",
                                 "FAILED test_wrong.py::test_agrees_with_the_plant*"])


def test_the_logs_are_made_once_and_read_back(tmp_path):
    class Config:  # what session_logs reads of pytest's config
        class cache:  # noqa: N801
            @staticmethod
            def mkdir(name):
                (tmp_path / name).mkdir(exist_ok=True)
                return tmp_path / name

        @staticmethod
        def getini(name):
            return {"artic_seed": "0", "artic_logs": ["28-"]}[name]

    first = testing.session_logs(Config)
    (folder,) = tmp_path.glob("artic/logs-*")
    made = {p: p.stat().st_mtime_ns for p in folder.rglob("*.parquet")}
    again = testing.session_logs(Config)
    assert list(first) == list(again) == ["28-ramp-steer-reverse-unloaded-30deg-6kph-right"]
    assert {p: p.stat().st_mtime_ns for p in folder.rglob("*.parquet")} == made
    assert first[list(first)[0]].frame.equals(again[list(again)[0]].frame)
    log = first[list(first)[0]]
    assert log.meta["seed"] == 0 and log.meta["direction"] == "reverse"


def test_the_vehicle_comes_from_the_ini_option_or_a_fixture(pytester):
    # In this process: artic_vehicle needs nothing that is not imported already.
    pytester.makeini("[pytest]\nartic_vehicle = six-axle\n")
    pytester.makepyfile(test_ini="""
        def test_vehicle(artic_vehicle):
            assert artic_vehicle.name == "six-axle"
    """)
    sub = pytester.mkpydir("sub")
    (sub / "conftest.py").write_text(textwrap.dedent("""
        import pytest
        from artic.mjcf.vehicle import load_vehicle

        @pytest.fixture(scope="session")
        def artic_vehicle():
            return load_vehicle("gosar2022-loaded")
    """))
    (sub / "test_fixture.py").write_text(textwrap.dedent("""
        def test_vehicle(artic_vehicle):
            assert artic_vehicle.name == "gosar2022-loaded"
    """))
    pytester.runpytest("-q").assert_outcomes(passed=2)


def test_importing_the_plugin_loads_nothing_heavy():
    # Every pytest session of an environment with artic loads the plugin.
    code = ("import sys, json, artic.validation.testing; "
            "print(json.dumps(sorted(sys.modules)))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    loaded = {m.split(".")[0] for m in json.loads(out.stdout)} | {
        m for m in json.loads(out.stdout) if m.startswith("artic.")}
    assert not loaded & {"numba", "mujoco", "pandas", "rerun", "artic.plant", "artic.reduced",
                         "artic.validation.harness.loop"}, loaded


def test_within_is_checked():
    log = straight_log(n=50, u=1.0)
    with pytest.raises(ValueError, match="unknown criterion 'eps_x'; choose from eps_y1"):
        assert_tracks("kin", log, within={"eps_x": 1.0}, vehicle="gosar2022-unloaded")
    with pytest.raises(ValueError, match="eps_p = nan: a limit is a finite number"):
        assert_tracks("kin", log, within={"eps_p": math.nan}, vehicle="gosar2022-unloaded")
    with pytest.raises(ValueError, match="give at least one criterion"):
        assert_agree("kin", "stm", log, within={}, vehicle="gosar2022-unloaded")
    with pytest.raises(ValueError, match="its metadata names no vehicle; pass vehicle="):
        assert_tracks("kin", log, within={"eps_p": 1.0})


def test_a_model_class_is_built_from_the_vehicle():
    # The README's and the models guide's call: a class is a builder of models,
    # not a model (it has reset and step, as functions of an instance).
    from artic.reduced import KIN

    log = straight_log(n=200, u=1.0)
    got = assert_agree("kin", KIN, log, within={"eps_p": 1e-9},
                       vehicle="gosar2022-unloaded")
    # KIN against KIN: the same steps from the same start, apart from rounding
    # in the reference's signals written back as a log (1e-16 m on a 10 m run).
    assert got["straight"]["eps_p"] < 1e-12
    with pytest.raises(TypeError, match="give a model name, a model, or a function"):
        assert_tracks(3.0, log, within={"eps_p": 1.0}, vehicle="gosar2022-unloaded")


def test_the_criteria_table():
    rows = [("fwd", {"eps_p": 0.5, "eps_n": math.nan}, "ok"),
            ("rev", {"eps_p": 2.0, "eps_n": 10.0}, "stopped at t = 3.00 s: jackknife")]
    table, failed = criteria_table(rows, {"eps_p": 1.0, "eps_n": 20.0})
    lines = table.splitlines()
    assert lines[0].split() == ["manoeuvre", "criterion", "value", "limit", "result"]
    assert lines[1].split() == ["fwd", "eps_p", "0.5", "m", "1", "m", "pass"]
    assert lines[2].split() == ["eps_n", "nan", "20", "%", "FAIL"]  # undefined is no pass
    assert lines[3].split() == ["rev", "eps_p", "2", "m", "1", "m", "FAIL"]
    assert lines[4].split() == ["eps_n", "10", "%", "20", "%", "pass"]
    assert lines[5] == "FAIL rev: stopped at t = 3.00 s: jackknife"
    assert failed == 3
    assert len({line.index("criterion") for line in lines[:1]}) == 1


def test_eps_gamma_of_kin_reversing_is_eq_6s_decay(unloaded):
    # KIN reversing straight from 3 deg, under the harness's default gain
    # (the paper's K = 3), with a steering map that centres at delta_h = 0:
    # gamma = gamma0 e^(lambda t) with eq. (6)'s lambda = u (K (L2 - L1c) -
    # L1) / (L1 L2), and the log's articulation is zero, so eps_gamma is the
    # time RMS of that decay. Within 1 %: the steering held over each 10 ms
    # step and the trapezoidal weights are of order |lambda| dt / 2 = 0.3 %,
    # the tan and sin of 3 and 9 deg less.
    from artic.reduced.kinematic import kin_parameters
    from artic.validation.harness.loop import DEFAULT_GAIN

    v = dataclasses.replace(unloaded, steering=dataclasses.replace(
        unloaded.steering, delta_h_offset=0.0), steering_overrides={})
    u, g0, n = -0.8, math.radians(3.0), 400
    log = straight_log(n=n, u=u, gamma0=g0)
    L1, L1c, L2 = kin_parameters(v)
    lam = u * (DEFAULT_GAIN * (L2 - L1c) - L1) / (L1 * L2)
    T = (n - 1) * 0.01
    expected = g0 * math.sqrt(math.expm1(2 * lam * T) / (2 * lam * T))
    got = assert_tracks("kin", log, within={"eps_gamma": 1.01 * expected}, vehicle=v)
    np.testing.assert_equal(got, assert_tracks("kin", log, {"eps_gamma": 1.0}, vehicle=v,
                                               gain=DEFAULT_GAIN))  # NaN: eps_n undefined
    assert got["straight"]["eps_gamma"] > 0.99 * expected
    with pytest.raises(AssertionError, match=r"eps_gamma .* rad .* FAIL"):
        assert_tracks("kin", log, within={"eps_gamma": 0.99 * expected}, vehicle=v)
    assert testing.DEFAULT_LOGS[0].startswith("00-") and testing.DEFAULT_VEHICLE
