"""Models from outside artic: registered in the process, or by an entry point.

A registered model must reach every place a built-in one does (``--models``,
the harness, the metrics, the tables, the recordings, tuning) with no change
to artic, and every way of registering one wrongly must say what is wrong.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import textwrap
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import artic
from artic.mjcf.vehicle import load_vehicle
from artic.mjcf.writer import updated, write_vehicle
from artic.reduced import KIN, Driven
from artic.validation import models
from artic.validation.cli.commands import main
from artic.validation.criteria.metrics import CRITERIA
from artic.validation.models import (
    NAMES,
    REGISTRY,
    ModelSpec,
    build,
    names,
    register_model,
    spec,
    unregister_model,
)
from tests.test_cli import constant_steer_logs


class KinBlue(KIN):
    """KIN itself under another name and colour: its results must be KIN's, digit for digit."""

    name = "kin_blue"


class PythonKin:
    """A model of the user's own: KIN's equations behind the minimal protocol.

    No compiled form, no loop of its own, nothing to close (all optional):
    the harness drives it through its Python loop, step by step, where the
    built-in KIN runs the compiled loop: the same law, the same steps.
    """

    name = "kin_py"

    def __init__(self, vehicle):
        self._kin = Driven(KIN(vehicle))

    def reset(self, initial):
        self._kin.reset(initial)

    def step(self, dt, delta, u1, u1_dot):
        self._kin.step(dt, delta, u1, u1_dot)

    def observe(self, delta=None):
        return self._kin.observe(delta)

    @property
    def gamma(self):
        return self._kin.gamma


@pytest.fixture
def registered():
    specs = [register_model("kin_blue", KinBlue, colour=(0, 0, 255), batched=True,
                            tuned=("i_s", "delta_h_offset")),
             register_model("kin_py", PythonKin, label="KIN-py")]
    yield specs
    for s in specs:
        unregister_model(s.name)


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    return constant_steer_logs(tmp_path_factory.mktemp("logs"))


def kin_map_for(tmp_path, *models) -> Path:
    """The unloaded preset with KIN's steering map ([steering.kin]) for each of ``models``."""
    kin = load_vehicle("gosar2022-unloaded").steering_overrides["kin"]
    data = updated("gosar2022-unloaded", {f"steering.{m}": kin for m in models},
                   "test: KIN's steering map for the registered models")
    path = tmp_path / "kin-map.toml"
    write_vehicle(data, path)
    return path


def test_the_registry_lists_built_ins_first_then_registered(registered):
    assert names() == (*NAMES, "kin_blue", "kin_py") == artic.model_names()
    # The built-ins first, the paper's three leading the tables, the floor among
    # them; registered models after, in the order they were registered.
    assert NAMES[:3] == ("kin", "stm", "mbd")
    builtin = list(models._BUILTIN)
    assert list(REGISTRY) == [*builtin, "kin_blue", "kin_py"] and "floor" in builtin
    assert artic.register_model is register_model
    assert spec("KIN_BLUE").label == "KIN_BLUE" and spec("kin_py").label == "KIN-py"
    assert spec("kin_py").colour not in {s.colour for s in REGISTRY.values() if s is not
                                         spec("kin_py")}
    unregister_model("kin_py")
    assert "kin_py" not in names() and "kin_py" not in REGISTRY
    register_model("kin_py", PythonKin, label="KIN-py")  # for the fixture to remove


def test_a_registered_model_is_validated_through_the_command_line(tmp_path, logs, registered,
                                                                  capsys):
    from artic.validation.review.recording import read_column

    out = tmp_path / "val"
    vehicle = kin_map_for(tmp_path, "kin_blue", "kin_py")
    assert main(["validate", *logs, "--vehicle", str(vehicle), "--models", "kin,kin_blue,KIN_PY",
                 "--out-dir", str(out)]) == 0
    printed = capsys.readouterr().out
    m = pd.read_csv(out / "metrics.csv")
    assert sorted(set(m.model)) == ["kin", "kin_blue", "kin_py"] and (m.status == "ok").all()
    per = {name: g.sort_values("log")[list(CRITERIA)].to_numpy() for name, g in m.groupby("model")}
    # The same class with the same steering map: KIN's numbers, digit for digit.
    np.testing.assert_array_equal(per["kin_blue"], per["kin"])
    # The Python loop against the compiled one: the same law and steps; the
    # CSV keeps 6 digits, and the two loops' rounding differs far below that.
    np.testing.assert_allclose(per["kin_py"], per["kin"], rtol=1e-5, equal_nan=True)
    table = pd.read_csv(out / "table2_forward.csv", index_col="model")
    assert list(table.index) == ["kin", "kin_blue", "kin_py"] and (table.n == 2).all()
    assert "| kin_blue |" in printed and "| kin_py |" in printed
    run = pd.read_parquet(out / "runs" / "left.kin_py.parquet")
    assert len(run) == 2001
    # The recording draws each model in its registry colour (RGBA packed in 32 bits).
    rec = out / "recordings" / "left.rrd"
    sources = read_column(rec, "/signals/articulation", "SeriesLines:names")[0]
    colours = read_column(rec, "/signals/articulation", "SeriesLines:colors")[0]
    assert sources == ["measured", "kin", "kin_blue", "kin_py"]
    assert colours[2] == 0x0000FFFF
    r, g, b = spec("kin_py").colour
    assert colours[3] == (r << 24) | (g << 16) | (b << 8) | 0xFF
    assert read_column(rec, "/yard/kin_blue/tractor", "Transform3D:translation")


def test_a_registered_model_is_tuned_into_its_own_steering_table(tmp_path, logs, registered,
                                                                 capsys):
    tuned = tmp_path / "tuned.toml"
    vehicle = kin_map_for(tmp_path, "kin_blue")
    assert main(["tune", *logs, "--vehicle", str(vehicle), "--models", "kin_blue,kin_py",
                 "--out", str(tuned)]) == 0
    printed = capsys.readouterr().out
    after = {m: float(a) for m, a in re.findall(r"^(\w+) +eps_n before [\d.]+ %, after ([\d.]+)",
                                                printed, re.M)}
    # kin_py tunes nothing: one evaluation, its error as it was.
    assert re.search(r"^kin_py +eps_n before ([\d.]+) %, after \1 % \(1 evaluations", printed,
                     re.M), printed
    v = load_vehicle(tuned)
    fitted = v.steering_overrides["kin_blue"]
    assert set(fitted) == {"i_s", "delta_h_offset"} and "kin_py" not in v.steering_overrides
    assert fitted["i_s"] != pytest.approx(20.5, rel=1e-3)  # it moved: the logs are the STM's
    # The file validates, and validation with it finds the fit's own error
    # (tuning minimises the same normalised terms that eps_n adds up).
    out = tmp_path / "val"
    assert main(["validate", *logs, "--vehicle", str(tuned), "--models", "kin_blue",
                 "--no-recordings", "--out-dir", str(out)]) == 0
    m = pd.read_csv(out / "metrics.csv")
    assert m.eps_n.mean() == pytest.approx(after["kin_blue"], abs=1e-3)


def test_registering_wrongly_says_what_is_wrong(registered):
    with pytest.raises(ValueError, match="'kin' is artic's built-in KIN; choose another"):
        register_model("kin", KinBlue)
    with pytest.raises(ValueError, match="'kin_blue' is registered already"):
        register_model("kin_blue", KinBlue)
    for bad in ("Kin Blue", "", "9kin", "a" * 33, "kin-blue"):
        with pytest.raises(ValueError, match="lower-case letters"):
            register_model(bad, KinBlue)
    with pytest.raises(ValueError, match="tunes its steering map only"):
        register_model("kin_f", KinBlue, tuned=("f",))
    with pytest.raises(ValueError, match="three integers 0-255"):
        register_model("kin_red", KinBlue, colour=(300, 0, 0))
    with pytest.raises(TypeError, match="build must be a function"):
        register_model("kin_none", "KinBlue")
    with pytest.raises(ValueError, match="'kin_none' is not a registered model"):
        unregister_model("kin_none")
    with pytest.raises(ValueError, match="not a registered model"):
        unregister_model("kin")
    assert "kin_f" not in names() and "kin_red" not in names()
    with pytest.raises(ValueError, match=re.escape(f"choose from {', '.join(names())}")):
        spec("kin_green")
    assert names()[-2:] == ("kin_blue", "kin_py")  # the registered ones are choices too


def test_a_build_that_breaks_the_protocol_is_a_failed_row(tmp_path, logs, capsys):
    v = load_vehicle("gosar2022-unloaded")
    register_model("not_a_model", lambda vehicle: object())
    register_model("kin_misnamed", KIN)
    try:
        # The minimal protocol: compiled(), closed_loop() and close() are optional.
        with pytest.raises(TypeError, match=r"lacks name, reset, step, observe, gamma of the "
                                            r"model protocol"):
            build("not_a_model", v)
        with pytest.raises(TypeError, match="a model named 'kin'; set its name to "
                                            "'kin_misnamed'"):
            build("kin_misnamed", v)
        out = tmp_path / "val"
        # The pairs without a result are rows that say why; the command says so by exit 1.
        assert main(["validate", logs[0], "--models", "kin,not_a_model", "--no-recordings",
                     "--out-dir", str(out)]) == 1
        m = pd.read_csv(out / "metrics.csv").set_index("model")
        assert m.loc["kin", "status"] == "ok"
        assert m.loc["not_a_model", "status"].startswith(
            "failed: TypeError: model 'not_a_model': its build returned a object")
    finally:
        unregister_model("not_a_model")
        unregister_model("kin_misnamed")


def test_a_misspelt_steering_table_is_refused_by_name(tmp_path, logs, capsys):
    data = updated("gosar2022-unloaded", {"steering.kni": {"i_s": 20.0}}, "test: a typo")
    path = tmp_path / "typo.toml"
    write_vehicle(data, path)  # the file format accepts a table for any model name
    assert main(["validate", logs[0], "--vehicle", str(path), "--out-dir",
                 str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert f"{path}: key 'steering.kni': no model 'kni' is registered" in err
    assert "did you mean kin?" in err and err.count("\n") == 1
    # artic vehicle show says the same; the library warns when it builds a model
    # (a table may be for a model registered in another process, and the vehicle
    # file is read before any is registered), and the build still runs.
    assert main(["vehicle", "show", str(path)]) == 2
    assert capsys.readouterr().err == err
    vehicle = artic.load_vehicle(path)
    with pytest.warns(models.SteeringTableWarning, match=r"key 'steering\.kni': no model 'kni' is "
                      r"registered .*did you mean kin\?.*uses the \[steering\] map"):
        build("kin", vehicle).close()
    preset = load_vehicle("gosar2022-unloaded")
    assert vehicle.steering_for("kin") == preset.steering_for("kin")  # kni's i_s 20 unused
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        build("kin", preset).close()  # the preset's tables name built-in models


ENTRY_MODULE = '''
from artic.reduced import KIN
from artic.validation.models import model_spec


class KinEp(KIN):
    name = "kin_ep"


SPEC = model_spec("kin_ep", KinEp, label="KIN-EP", colour=(200, 0, 200), batched=True)


def broken():
    raise RuntimeError("no licence for this model")
'''


# The artic command in a process of its own, on an installed distribution: end to end,
# in the slow set (issue 42, the fast suite's budget).
@pytest.mark.slow
def test_an_entry_point_registers_a_model_and_a_broken_one_is_one_line(tmp_path, logs):
    # A distribution installed the way pip leaves one: a module and its
    # .dist-info folder with entry_points.txt, on the path.
    site = tmp_path / "site"
    info = site / "demo_models-0.1.dist-info"
    info.mkdir(parents=True)
    (site / "demo_models.py").write_text(textwrap.dedent(ENTRY_MODULE))
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: demo-models\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(
        "[artic.models]\nkin_ep = demo_models:SPEC\nkin_broken = demo_models:broken\n")
    out = tmp_path / "val"
    env = {**os.environ, "PYTHONPATH": str(site)}
    artic_cmd = Path(sys.executable).parent / "artic"
    done = subprocess.run([str(artic_cmd), "validate", logs[0], "--models", "kin,kin_ep",
                           "--no-recordings", "--out-dir", str(out)],
                          capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    warned = [line for line in done.stderr.splitlines() if "warning" in line]
    assert warned == ["artic: warning: model entry point kin_broken = demo_models:broken of "
                      "demo-models (group artic.models) was not loaded: RuntimeError: no "
                      "licence for this model; the other models are available"]
    m = pd.read_csv(out / "metrics.csv")
    assert list(m.model) == ["kin", "kin_ep"] and (m.status == "ok").all()
    assert "| kin_ep |" in done.stdout
    # Not registered in this process: entry points reach the processes that look them up.
    assert "kin_ep" not in names()


def test_model_spec_is_a_checked_entry():
    s = artic.model_spec("kin_x", KinBlue)
    assert isinstance(s, ModelSpec) and s.label == "KIN_X" and s.tuned == () and not s.batched
    assert "kin_x" not in names()  # made, not registered


def test_the_report_names_a_registered_model_by_its_label(registered):
    from artic.validation.campaign.report import CampaignResults, discussion
    from artic.validation.review.tables import summary

    # Ten reverse manoeuvres on which the registered model is 10 points below
    # KIN on each one: the paired comparison resolves it, and the text names
    # it by its registry label.
    rng = np.random.default_rng(0)
    base = 85.0 + rng.normal(0.0, 5.0, 10)
    rows = [{"log": f"{i:02d}-docking", "manoeuvre": "docking", "model": m, "direction": "reverse",
             "status": "ok", "eps_a": 0.006, "eps_v": 0.03, "J_steer": 100.0 - d,
             "eps_n": b - d, "eps_p": 1.0}
            for i, b in enumerate(base) for m, d in (("kin", 0.0), ("kin_py", 10.0))]
    metrics = pd.DataFrame(rows)
    reverse = summary(metrics, "reverse")
    r = CampaignResults(seed=0, models=("kin", "kin_py"), gain=3.0, metrics=metrics,
                        forward=reverse.iloc[:0], reverse=reverse, tuned={}, efficiency=None,
                        sweep=None, stages={}, fingerprint="", version="")
    text = "\n".join(discussion(r))
    assert "KIN-py" in text and "kin_py" not in text
    # Beside the paper's Table 3: the registered model is not in the paper.
    assert "KIN-py" in text.split("Table 3.**", 1)[1] and "(not in the paper)" in text
    assert "nan" not in text


def test_a_renamed_kin_steers_as_kin_unless_its_file_gives_it_a_map(tmp_path, logs):
    # A subclass of KIN with another name took the file's generic [steering] map instead of
    # KIN's (issue 46, item 16): a pure rename changed eps_p from 0.50 m to 0.32 m.
    from artic.validation.models import steering_name

    v = load_vehicle("gosar2022-unloaded")
    assert "kin" in v.steering_overrides and "kin_blue" not in v.steering_overrides
    assert steering_name(v, KinBlue(v)) == "kin"
    log = artic.read_log(logs[0], vehicle=v)
    kin = artic.run_closed_loop(KIN(v), log, v).frame
    blue = artic.run_closed_loop(KinBlue(v), log, v).frame
    for c in ("x_1", "y_1", "psi_1", "gamma", "delta"):
        np.testing.assert_array_equal(blue[c].to_numpy(), kin[c].to_numpy(), err_msg=c)
    # A table of its own is its own, by the model or by its registered name.
    register_model("kin_blue", KinBlue)
    try:
        own = write_vehicle(updated("gosar2022-unloaded", {"steering.kin_blue": {"i_s": 20.0}},
                                    "test"), tmp_path / "own.toml")
        assert steering_name(own, KinBlue(own)) == "kin_blue"
        assert steering_name(own, "kin_blue") == "kin_blue"
        assert steering_name(v, "kin_blue") == "kin"  # through the registered class
    finally:
        unregister_model("kin_blue")


class Overflows(PythonKin):
    """KIN's equations, until its position overflows every physical range after 5 s."""

    name = "overflows"

    def reset(self, initial):
        super().reset(initial)
        self.t = 0.0

    def step(self, dt, delta, u1, u1_dot):
        super().step(dt, delta, u1, u1_dot)
        self.t += dt

    def observe(self, delta=None):
        o = np.array(super().observe(delta), dtype=float)
        if self.t > 5.0:
            o[0] = 1e300  # finite, so it passed; eps_p came out inf with the status ok
        return o


def test_a_model_whose_output_leaves_every_physical_range_stops_with_a_status(logs):
    v = load_vehicle("gosar2022-unloaded")
    log = artic.read_log(logs[0], vehicle=v)
    run = artic.run_closed_loop(Overflows(v), log, v)
    status = run.meta["status"]
    assert status.startswith("stopped at t = 5.0") and "x_1 = 1e+300 left the range a " \
        "model's output may have (|x_1| <= 1e+07 SI)" in status, status
    assert np.all(np.abs(run.frame["x_1"].to_numpy()) < 1e7) or len(run.frame) < len(log.frame)


def test_an_open_loop_run_of_such_a_model_stops_too():
    v = load_vehicle("gosar2022-unloaded")
    run = artic.simulate(Overflows(v), v, artic.make_profile("constant-steer", duration=8.0))
    assert run.meta["status"].startswith("stopped at t = 5.0") and "x_1 = 1e+300" in \
        run.meta["status"], run.meta["status"]
    assert float(run.frame["x_1"].abs().max()) < 1e3  # the sound samples only [m]
