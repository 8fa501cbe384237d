"""The floor predicts itself: from the truth's own state, its open-loop predictions are exact.

The open-loop predictions (:mod:`artic.validation.criteria.prediction`) start
the floor, the truth of each log, from the truth's full state at each start
point, which generation records (``full_state()``; ``set_full_state()``
restores it). On the truth's noise-free logs (ideal sensors, the column's
drift stilled) its 10 m prediction must then be within 1 cm and 0.05 deg at
every start point (the issue's figures).

The floor replays what the truth was given: generation records, at every
step, the truth's steering demand and its driver's pedals
(``meta["truth_actuation"]``), and the floor's prediction takes them instead of
the harness's inputs (:class:`artic.validation.criteria.prediction.Replay`).
Driven instead by the harness's speed follower, as every model under
validation is, the floor spread the drive and braking over the wheels
otherwise than the driver's pedals did, and on the docking and parking
manoeuvres' shuffles at full lock it missed its own 10 m by up to 6.6 cm
(seed 0, yard truth). Replaying, its state and its inputs are the truth's: it
retraces its log to rounding, at every start point.
"""

from __future__ import annotations

import math

import numpy as np
import pyarrow.parquet as pq
import pytest

from artic.mjcf.interface import InitialState
from artic.validation.criteria.prediction import (
    ACTUATION_FIELDS,
    Replay,
    prediction_errors,
    record_actuation,
    recorded_actuation,
    truth_states,
)
from artic.validation.logs.importers import import_source
from artic.validation.logs.runfile import META_KEY, parse_meta
from artic.validation.models import build
from artic.validation.synthetic.floor import floor_replay
from artic.validation.synthetic.generate import simulate_manoeuvre, write_export
from artic.validation.synthetic.sensors import SensorModel
from artic.validation.synthetic.testmatrix import MATRIX
from artic.validation.synthetic.truth import truth_configuration, truth_vehicle
from artic.validation.synthetic.truthplant import TruthPlant

SEED = 0
# The bounds at 10 m, at every start point, held at every horizon and
# every log. The replay is exact but for the export's digits (positions to
# 0.1 mm, angles to 1e-6 rad) and the start point's sample: the measured side
# of the comparison is the exported log, so the bounds are far from tight
# (seed 0, 152 start points: at most 0.014 mm and 1e-5 deg), but they are the
# issue's, which the follower missed by 6.6 cm on one docking shuffle.
P_MAX = 0.01  # [m]
GAMMA_MAX = math.radians(0.05)  # [rad]
REVERSE = [m for m in MATRIX if m.direction == "reverse"]


def noise_free(m, tmp_path):
    """``m``'s log as the campaign reads it: ideal sensors, no drift, exported and imported."""
    made = simulate_manoeuvre(m, SEED, SensorModel.ideal(), "independent", drift=False)
    log, repairs = import_source(write_export(made, tmp_path))
    assert repairs == []
    return log, truth_vehicle(m.load, log.meta["truth"], SEED, log.meta["slope"])


def floor_errors(log, vt, states) -> dict:
    floor = floor_replay(vt, log)  # as the campaign's floor row predicts
    assert isinstance(floor, Replay)
    try:
        return prediction_errors(floor, log, vt, states=states, per_start=True)
    finally:
        floor.close()


def check_every_start(got: dict) -> None:
    per = got["per_start"]
    assert got["left_out"] == 0 and got["stopped"] == 0, got["note"]
    scored = np.isfinite(per["p"])
    assert scored[:-1, 0].all()  # only the last start point may lack 2 m of log after it
    # Every horizon, every start point scored (not only the 10 m ones).
    assert np.all(per["p"][scored] <= P_MAX), per["p"]
    assert np.all(per["gamma"][scored] <= GAMMA_MAX), np.degrees(per["gamma"])


def test_the_truth_continues_from_its_full_state():
    m = REVERSE[0]
    vt = truth_vehicle(m.load, truth_configuration(SEED, drift=False), SEED)
    start = InitialState(0.0, 0.0, 0.3, math.radians(5.0), u1=-1.0)

    def drive(plant, n):
        out = []
        for k in range(n):
            plant.step(0.01, math.radians(10.0) * math.sin(0.05 * k), -1.0, 0.0)
            out.append(plant.observe())
        return np.array(out)

    with TruthPlant(vt) as a, TruthPlant(vt) as b:
        a.reset(start)
        drive(a, 150)  # the column twisted, the assist and the tyres loaded
        x = a.full_state()
        assert x.dtype == np.float64
        ahead = drive(a, 100)
        b.set_full_state(x)  # another truth of the same vehicle
        again = drive(b, 100)
        # MuJoCo's data after a step hold what its last integrator stage
        # computed; a restored state has them computed afresh at the state:
        # the continuation agrees to rounding, 1e-10 m and rad over 1 s.
        np.testing.assert_allclose(again, ahead, rtol=0.0, atol=1e-9)
        a.set_full_state(x)  # the same truth, after it went on: the restored run, to the bit
        np.testing.assert_array_equal(drive(a, 100), again)
        with pytest.raises(ValueError, match="another vehicle"):
            a.set_full_state(x[:-1])


def test_the_floor_predicts_a_short_noise_free_log_from_its_own_states(tmp_path):
    log, vt = noise_free(REVERSE[0], tmp_path)  # 47 s, four start points
    states = truth_states(log.meta)
    assert states is not None and states.x.shape[1] > 100
    got = floor_errors(log, vt, states)
    assert got["starts"] >= 3
    check_every_start(got)
    # Started with its hidden states zeroed (as before), the same truth misses
    # its own 10 m by millimetres and hundredths of a degree on this gentle log.
    model = build("floor", vt, log)
    try:
        zeroed = prediction_errors(model, log, vt)
    finally:
        model.close()
    assert zeroed["pred_gamma_10m"] > 10.0 * got["pred_gamma_10m"]


def test_the_campaigns_floor_row_starts_from_the_states(tmp_path):
    from artic.validation.runs.validate import validate_runs

    log, vt = noise_free(REVERSE[0], tmp_path)
    rows = validate_runs([log], vt, ["floor"])
    row = rows.iloc[0]
    assert row["pred_p_10m"] <= P_MAX and row["pred_gamma_10m"] <= GAMMA_MAX
    # A log that holds no states: the truth cannot start consistently anywhere.
    bare = type(log)(log.frame, {k: v for k, v in log.meta.items() if k != "truth_state"})
    rows = validate_runs([bare], vt, ["floor"])
    assert rows[["pred_p_2m", "pred_gamma_10m"]].isna().all().all()


def test_the_truth_replays_its_log_from_its_state_and_actuation():
    # The truth restored at a start point and given, step by step, what it was
    # given making the log retraces it: the state is the truth's whole state
    # and the recorded actuation all it was driven by.
    m = REVERSE[0]
    log = simulate_manoeuvre(m, SEED, SensorModel.ideal(), "independent", drift=False)
    states, held = truth_states(log.meta), recorded_actuation(log.meta)
    frame = log.frame
    assert held is not None and len(held.x) >= len(frame) - 1
    assert np.any(held.x[:, 3] > 0.0) and np.any(held.x[:, 4] > 0.0)  # throttle and brake
    t = float(states.t[3])  # at 10 m
    k = held.index(t)
    assert k is not None and frame["t"].iloc[k] == t
    vt = truth_vehicle(m.load, log.meta["truth"], SEED, log.meta["slope"])
    replay = floor_replay(vt, log)
    try:
        replay.start(states.at(t), k)
        got = [replay.observe()]
        for _ in range(1000):  # 10 s, about 8 m; the harness's inputs are not used
            replay.step(0.01, float("nan"), float("nan"), float("nan"))
            got.append(replay.observe())
    finally:
        replay.close()
    want = frame.iloc[k:k + len(got)]
    # Rounding only: this log was not exported, and the restored data differ
    # from a stepped one's by 1e-11.
    np.testing.assert_allclose(np.array(got)[:, [6, 7, 12]],
                               want[["x_2", "y_2", "gamma"]].to_numpy(), rtol=0.0, atol=1e-8)
    with pytest.raises(ValueError, match="recorded state"):
        replay.reset(InitialState(0.0, 0.0, 0.0, 0.0))


def test_the_recorded_actuation_round_trips_and_refuses_damage():
    rng = np.random.default_rng(0)
    x = rng.normal(size=(50, len(ACTUATION_FIELDS)))
    rec = record_actuation(x, "pedals", 0.01, 2.0)
    got = recorded_actuation({"truth_actuation": rec})
    np.testing.assert_array_equal(got.x, x)  # to the bit: the floor replays it exactly
    assert got.speed == "pedals" and got.index(2.0) == 0 and got.index(2.49) == 49
    assert got.index(2.5) is None and got.index(2.005) is None  # past the end, between samples
    assert recorded_actuation({}) is None
    from artic.mjcf.errors import UserError

    with pytest.raises(UserError, match="truth_actuation.*generate the log again"):
        recorded_actuation({"truth_actuation": rec | {"x": rec["x"][:-8]}})


def test_a_log_without_actuation_has_the_follower_say_so(tmp_path):
    from artic.validation.runs.validate import FOLLOWED, _predict

    log, vt = noise_free(REVERSE[0], tmp_path)
    old = type(log)(log.frame, {k: v for k, v in log.meta.items() if k != "truth_actuation"})
    assert floor_replay(vt, old) is None
    floor = build("floor", vt, old)
    try:
        got = _predict(floor, old, vt, "floor")
    finally:
        floor.close()
    assert FOLLOWED in got["note"] and got["starts"] >= 3
    # The follower on this gentle ramp steer: millimetres (seed 0: 2.6 mm).
    assert got["pred_p_10m"] <= P_MAX


@pytest.mark.slow
@pytest.mark.parametrize("m", REVERSE, ids=lambda m: m.name)
def test_the_floor_predicts_every_reverse_log_from_its_own_states(m, tmp_path):
    # Every reverse log of seed 0, the docking and parking shuffles at full lock
    # included (the follower missed one of them by 6.6 cm at 10 m): within the
    # issue's 1 cm and 0.05 deg at every start point and horizon.
    log, vt = noise_free(m, tmp_path)
    check_every_start(floor_errors(log, vt, truth_states(log.meta)))


@pytest.fixture(scope="module")
def log_and_twin(tmp_path_factory):
    """A measured reverse log and its noise-free twin, exported and imported as the campaign's."""
    m = REVERSE[0]
    tmp = tmp_path_factory.mktemp("twin")
    log_run, twin_run = simulate_manoeuvre(m, SEED, None, "independent", twin=True)
    (tmp / "logs").mkdir()
    (tmp / "twins").mkdir()
    log, _ = import_source(write_export(log_run, tmp / "logs", name=m.name))
    twin, _ = import_source(write_export(twin_run, tmp / "twins", name=m.name,
                                         meta_from=tmp / "logs" / m.name))
    return m, log, twin


def test_the_twin_reuses_the_logs_replay_runs_to_the_bit(log_and_twin):
    """The floor's replay ignores what the sensors measured, so a twin reuses the log's runs.

    The campaign's twins stage takes the references' replay runs instead of
    running them again (:class:`artic.validation.criteria.prediction.ReplayRuns`):
    its errors must be the ones it computes alone, bit for bit, and the log's
    own errors must not change for running its replays a margin longer.
    """
    from artic.validation.criteria.prediction import COLUMNS, ReplayRuns

    m, log, twin = log_and_twin

    def errors(run, share=None):
        # Each log's truth vehicle built afresh, as the campaign's floor builds it.
        vt = truth_vehicle(m.load, run.meta["truth"], SEED, run.meta["slope"])
        floor = floor_replay(vt, run)
        try:
            return prediction_errors(floor, run, vt, states=truth_states(run.meta),
                                     per_start=True, share=share)
        finally:
            floor.close()

    alone, kept = errors(log), errors(log, True)
    shared = kept.pop("replays")
    assert isinstance(shared, ReplayRuns) and len(shared.runs) >= 3
    twin_alone, twin_shared = errors(twin), errors(twin, shared)
    reused = twin_shared.pop("replays").runs
    # Most start points are the same samples on the log and on its twin (their
    # travelled distances differ by the speed noise): some runs must be reused.
    assert sum(reused[k] is shared.runs.get(k) for k in reused) >= 1, (list(reused),
                                                                         list(shared.runs))
    for got, want in ((kept, alone), (twin_shared, twin_alone)):
        for c in (*COLUMNS, "starts", "left_out", "stopped", "note"):
            assert got[c] == want[c] or (got[c] != got[c] and want[c] != want[c]), c
        for f in ("t", "p", "gamma"):
            np.testing.assert_array_equal(got["per_start"][f], want["per_start"][f])
    # Another truth run (the log's states changed) reuses nothing.
    other = ReplayRuns("not this run's digest", shared.runs)
    again = errors(twin, other)["replays"].runs
    assert again and not any(again[k] is shared.runs.get(k) for k in again)


def test_the_campaigns_twin_floor_rows_reuse_the_logs_replays(log_and_twin, tmp_path):
    """validate_runs hands the floor's replay runs on (never into a run file); rows unchanged."""
    from artic.validation.runs.validate import validate_runs

    m, log, twin = log_and_twin

    def vehicle_of(run):
        return truth_vehicle(m.load, run.meta["truth"], SEED, run.meta["slope"])

    def rows(run, replays=None, out=None):
        got = validate_runs([run], vehicle_of, ["floor"], replays=replays, out_dir=out,
                            samples=False)
        return got.drop(columns="wall_s")

    kept: dict = {}
    assert rows(log, kept, tmp_path).equals(rows(log))
    assert set(kept) == {log.name} and kept[log.name].runs
    path = tmp_path / "runs" / f"{log.name}.floor.parquet"
    meta = parse_meta(pq.read_metadata(path).metadata[META_KEY], str(path))
    assert "replays" not in meta["prediction"]  # kept in memory, not written
    assert rows(twin, kept).equals(rows(twin))
