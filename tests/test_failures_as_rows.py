"""A failing (log, model) pair is a metrics row, not an abort; the plant says when it failed."""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np
import pandas as pd
import pytest

from artic.plant import Plant, PlantError
from artic.validation.cli.commands import main
from artic.validation.logs.runfile import read_run, write_run
from artic.validation.plumbing.runtime import MujocoWarning
from artic.validation.review.tables import summary
from artic.validation.runs import validate as val
from tests.hostile_logs import docking, slalom

DIVERGE_AT = 5.0
"""When the deliberately absurd parameter is set [s]."""


@pytest.fixture()
def absurd_after_5_s(monkeypatch):
    """From t = 5 s on, gravity is 1e12 m/s^2: the plant's state blows up in its next step."""
    real = Plant.step

    def step(self, dt, delta, u1, u1_dot):
        if self.data.time >= DIVERGE_AT - 1e-9:
            self.model.opt.gravity[2] = -1e12
        return real(self, dt, delta, u1, u1_dot)

    monkeypatch.setattr(Plant, "step", step)
    # Through Plant.step, so the Python loop of the harness: the compiled loop
    # (tests/test_closedloop.py shows it raises the same error) never calls it.
    monkeypatch.setattr(Plant, "closed_loop", lambda self: None)


def test_plant_error_names_the_last_good_time_and_wheel(absurd_after_5_s, unloaded):
    from artic.validation.harness.loop import run_closed_loop

    with Plant(unloaded) as p, pytest.warns(MujocoWarning, match="unstable"):
        with pytest.raises(PlantError) as err:
            run_closed_loop(p, slalom(), unloaded)
        # MuJoCo reset the simulation (its clock shows the step after t = 0) ...
        assert p.data.time < 0.1
    # ... but the report gives the time the state was last sound, and the wheel.
    msg = str(err.value)
    assert msg.startswith("t = 5.000 s: the simulation diverged within the next 10 ms")
    wheel = msg.split("largest tyre force then at wheel ")[1].split(" (")[0]
    assert wheel in p.wheel_names
    assert float(msg.rsplit("(", 1)[1].split(" N)")[0]) > 1e3


def test_divergence_at_5_s_is_a_row_and_the_batch_completes(absurd_after_5_s, tmp_path,
                                                             capsys, monkeypatch):
    logs = [write_run(slalom(), tmp_path / "slalom.parquet"),
            write_run(docking(), tmp_path / "docking.parquet")]
    out = tmp_path / "val"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MujocoWarning)
        code = main(["validate", *map(str, logs), "--models", "kin,mbd", "--out-dir", str(out)])
    text = capsys.readouterr()
    assert code == 1  # something failed: said, after everything was written
    assert "2 (log, model) pair(s) failed" in text.out
    m = pd.read_csv(out / "metrics.csv")
    assert len(m) == 4
    mbd, kin = m[m.model == "mbd"], m[m.model == "kin"]
    assert (kin.status == "ok").all() and kin.eps_p.notna().all()
    for status in mbd.status:
        assert status.startswith("failed: t = 5.000 s: the simulation diverged"), status
    assert mbd.eps_p.isna().all() and (mbd.s_max == 0).all()
    # The run files record the failure, so a resumed batch does not repeat it.
    run = read_run(out / "runs" / "slalom.mbd.parquet", check=False)
    assert len(run.frame) == 0 and run.meta["status"] == mbd.status.iloc[0]
    # The tables use the pairs with results.
    t = summary(m, "forward")
    assert list(t.index) == ["kin"] and int(t.loc["kin", "n"]) == 1


def test_failures_are_reused_when_resuming(absurd_after_5_s, tmp_path, unloaded, monkeypatch):
    logs = [slalom()]
    calls = []
    real = val._simulate
    monkeypatch.setattr(val, "_simulate", lambda *a: calls.append(a[0]) or real(*a))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MujocoWarning)
        first = val.validate_runs(logs, unloaded, ["mbd"], out_dir=tmp_path, reuse_key="k")
        again = val.validate_runs(logs, unloaded, ["mbd"], out_dir=tmp_path, reuse_key="k")
    assert calls == ["mbd"]
    assert first.status.tolist() == again.status.tolist()


def test_a_refused_pair_is_a_row(tmp_path, unloaded):
    # KIN's own steering map folds inside the slalom's steering range (q = 0.3 /rad):
    # that model refuses the log; the STM runs it.
    v = dataclasses.replace(unloaded, steering_overrides={**unloaded.steering_overrides,
                                                          "kin": {"q": 0.3}})
    m = val.validate_runs([slalom()], v, ["kin", "stm"], out_dir=tmp_path)
    kin, stm = m.set_index("model").loc["kin"], m.set_index("model").loc["stm"]
    assert kin.status.startswith("refused: slalom: column delta_h: steering-wheel angle")
    assert math.isnan(kin.eps_n) and stm.status == "ok" and np.isfinite(stm.eps_p)


def test_a_model_that_cannot_be_built_is_a_row(tmp_path, unloaded, monkeypatch):
    real = val.build

    def build(name, vehicle, log=None):
        if name == "mbd":
            raise RuntimeError("no compiler and no numpy either")
        return real(name, vehicle, log)

    monkeypatch.setattr(val, "build", build)
    m = val.validate_runs([slalom()], unloaded, ["mbd", "kin"], out_dir=tmp_path)
    st = dict(zip(m.model, m.status, strict=True))
    assert st["mbd"] == "failed: RuntimeError: no compiler and no numpy either"
    assert st["kin"] == "ok"


def test_a_log_without_a_plant_run_is_left_out_against_the_plant(tmp_path, unloaded, capsys):
    # The plant refused one log (its row says why); the comparison of KIN with
    # the plant skips that log instead of failing on the empty run file.
    from artic.validation.campaign.main import _versus_plant
    from artic.validation.logs.runfile import write_run
    from artic.validation.runs.validate import failed_run
    from tests.helpers import as_log, straight_log

    log = as_log(straight_log(n=300), "refused-by-the-plant")
    log.meta.update(load="unloaded", direction="reverse", manoeuvre="docking")
    (tmp_path / "runs").mkdir()
    write_run(failed_run(log, "mbd", unloaded, 3.0, "refused: eq. (3) folds back"),
              tmp_path / "runs" / f"{log.name}.mbd.parquet")
    out = _versus_plant(tmp_path, [log], {"unloaded": unloaded}, ("kin",), 3.0, "k", jobs=1)
    assert out is None
    assert "refused-by-the-plant has no plant run (refused: eq. (3) folds back)" in \
        capsys.readouterr().err
