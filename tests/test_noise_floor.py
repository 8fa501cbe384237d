"""Declared sensor noise and the noise floor artic validate prints from it.

The floor is what a perfect model scores from the declared noise alone. On
synthetic logs made through the default sensors, whose noise-free twins
(ideal sensors, the same seed: the same truth run) are known, the floor
printed for KIN's runs must be what the noise did to the logs: the criteria
between each log and its twin.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pandas as pd
import pytest

from artic.mjcf.vehicle import load_vehicle
from artic.validation.cli.commands import main
from artic.validation.criteria import columns as extra
from artic.validation.criteria.metrics import run_metrics
from artic.validation.criteria.noisefloor import DRAWS, FLOORED, floor_draws, summarise
from artic.validation.logs.noise import (
    ChannelNoise,
    add_noise,
    noise_sequence,
    parse_noise,
    read_noise,
)
from artic.validation.logs.runfile import LogError, Run, read_run, write_run
from artic.validation.synthetic.generate import simulate_manoeuvre
from artic.validation.synthetic.sensors import SensorModel
from artic.validation.synthetic.testmatrix import MATRIX
from tests.helpers import straight_log

NAMES = ("00-constant-steer-unloaded-200deg-5kph-left",
         "01-constant-steer-unloaded-200deg-5kph-right",
         "27-ramp-steer-reverse-unloaded-30deg-6kph-left",
         "28-ramp-steer-reverse-unloaded-30deg-6kph-right")
"""Two forward and two reverse logs of the truth, about 40 s each."""


def declaration(sensors: SensorModel, trailer_white: float = 1.0) -> str:
    """The [noise] table of the synthetic measurement chain's figures (``SensorModel``).

    ``trailer_white`` scales the semitrailer's white channels: the chain
    resamples that unit's signals at its clock skew, which averages two
    neighbouring samples of white noise (see the twin test).
    """
    s = sensors
    lines = ["[noise]"]
    for i in (1, 2):
        g = trailer_white if i == 2 else 1.0
        lines += [f"x_{i} = {{ sigma = {s.pos_sigma}, tau = {s.pos_tau} }}",
                  f"y_{i} = {{ sigma = {s.pos_sigma}, tau = {s.pos_tau} }}",
                  f'psi_{i} = {{ sigma = {math.degrees(s.heading_sigma)}, unit = "deg", '
                  f"tau = {s.heading_tau} }}",
                  f"v_x_{i} = {{ sigma = {g * s.vel_sigma} }}",
                  f"v_y_{i} = {{ sigma = {g * s.vel_sigma} }}",
                  f'r_{i} = {{ sigma = {g * math.degrees(s.rate_sigma)}, '
                  f'bias = {math.degrees(s.rate_bias_sigma)}, unit = "deg/s" }}']
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------ declarations

def test_a_declaration_is_made_si(tmp_path):
    path = tmp_path / "noise.toml"
    path.write_text(declaration(SensorModel()))
    got = read_noise(path)
    assert set(got) == {f"{c}_{i}" for i in (1, 2) for c in ("x", "y", "psi", "v_x", "v_y", "r")}
    assert got["psi_1"] == ChannelNoise(math.radians(0.05), 10.0, 0.0)
    assert got["r_2"].bias == pytest.approx(math.radians(0.01), rel=1e-12)
    assert got["v_y_1"] == ChannelNoise(0.01)


@pytest.mark.parametrize(("text", "message"), [
    ("x_1 = { sigma = -0.01 }", r"noise.toml: noise.x_1: sigma = -0.01; a sigma \[m\] is >= 0"),
    ("delta_h = { sigma = 0.1 }", r"noise.toml: noise.delta_h: not a channel whose noise the "
                                  r"criteria see; declare x_1, "),
    ("r_1 = { sigma = 0.1, tau = -1 }", r"noise.r_1: tau = -1; a tau \[s\] is >= 0"),
    ("r_1 = { sigma = 0.1, unit = \"m\" }", r"noise.r_1: unit 'm' is not a unit of rate; use "
                                            r"one of rad/s, deg/s"),
    ("y_2 = { sigma = 0.1, corr = 5 }", r"noise.y_2: unknown key\(s\) corr; use sigma, tau"),
    ("y_2 = { tau = 5 }", r"noise.y_2: give a table with sigma"),
    ("y_2 = { sigma = nan }", r"noise.y_2: sigma = nan; give a finite number"),
])
def test_a_bad_declaration_names_the_file_and_key(tmp_path, text, message):
    path = tmp_path / "noise.toml"
    path.write_text(f"[noise]\n{text}\n")
    with pytest.raises(LogError, match=message):
        read_noise(path)


@pytest.mark.parametrize(("text", "message"), [
    # 5 meant in degrees, read as radians (286 deg)
    ("psi_1 = { sigma = 5 }", r"noise.psi_1: sigma = 5 rad is beyond any sensor of its kind "
                              r"\(dual-antenna GNSS/INS heading 0.1-0.2 deg.*refused above "
                              r"0.349 rad\); check the value and its unit"),
    ("x_1 = { sigma = 1e9 }", r"noise.x_1: sigma = 1e\+09 m is beyond any sensor .*RTK GNSS/INS "
                              r"0.01-0.02 m.*refused above 10 m"),
    ("x_2 = { sigma = 1e300 }", r"noise.x_2: sigma = 1e\+300 m is beyond any sensor"),
    ("r_1 = { sigma = 0.001, bias = 45, unit = \"deg/s\" }",
     r"noise.r_1: bias = 45 deg/s is beyond any sensor .*refused above 30 deg/s"),
    ("v_x_1 = { sigma = 20, unit = \"km/h\" }", r"noise.v_x_1: sigma = 20 km/h is beyond"),
])
def test_a_noise_no_sensor_of_its_kind_has_is_refused(tmp_path, text, message):
    # Any finite size was accepted, and the noise-floor table reported nonsense (issue 46,
    # item 5). The refusal bounds are ten times the usual (NOISE_RANGES).
    path = tmp_path / "noise.toml"
    path.write_text(f"[noise]\n{text}\n")
    with pytest.raises(LogError, match=message):
        read_noise(path)


def test_a_plausible_but_unusual_noise_is_a_warning_that_gives_the_usual_bounds(tmp_path):
    from artic.mjcf.plausible import PlausibilityWarning

    path = tmp_path / "noise.toml"
    path.write_text('[noise]\nx_1 = { sigma = 2.0 }\npsi_1 = { sigma = 0.15, unit = "deg" }\n')
    with pytest.warns(PlausibilityWarning, match=r"noise.x_1: sigma = 2 m is unusual: more "
                                                 r"than the usual 0.5 m \(RTK GNSS/INS"):
        got = read_noise(path)
    assert got["x_1"].sigma == 2.0  # kept: a standalone GNSS receiver has it
    assert got["psi_1"].sigma == pytest.approx(math.radians(0.15), rel=1e-12)  # no word


def test_a_file_without_a_noise_table_is_refused(tmp_path):
    path = tmp_path / "map.toml"
    path.write_text('[time]\ncolumn = "t"\nunit = "s"\n')
    with pytest.raises(LogError, match=r"map.toml: no \[noise\] table"):
        read_noise(path)


def test_the_noise_has_its_declared_spread_and_correlation():
    # White: the sample standard deviation of 200 000 draws is within 1 % (its
    # relative standard error is 1/sqrt(2 n) = 0.16 %). Gauss-Markov: its lag-k
    # correlation is exp(-k dt / tau); 200 000 samples of 0.01 s hold 200
    # correlation times of 10 s, so the estimates are good to about 1/sqrt(200):
    # 10 % on the spread, 0.1 on the correlation at one tau.
    rng = np.random.default_rng(1)
    n, dt = 200_000, 0.01
    white = noise_sequence(rng, n, dt, ChannelNoise(0.02))
    assert white.std() == pytest.approx(0.02, rel=0.01)
    assert abs(np.corrcoef(white[:-1], white[1:])[0, 1]) < 0.01
    gm = noise_sequence(rng, n, dt, ChannelNoise(0.02, tau=10.0))
    assert gm.std() == pytest.approx(0.02, rel=0.1)
    k = int(10.0 / dt)
    assert np.corrcoef(gm[:-k], gm[k:])[0, 1] == pytest.approx(math.exp(-1.0), abs=0.1)
    # A bias is one constant per sequence: its spread over sequences is declared.
    biases = [noise_sequence(rng, 10, dt, ChannelNoise(0.0, bias=0.5)) for _ in range(2000)]
    assert all(np.ptp(b) == 0.0 for b in biases)
    assert np.std([b[0] for b in biases]) == pytest.approx(0.5, rel=0.05)


def test_the_articulation_follows_the_noisy_headings_unless_declared():
    log = straight_log(500, u=1.0).frame
    rng = np.random.default_rng(0)
    heads = parse_noise({"psi_1": {"sigma": 0.01}}, "t")
    out = add_noise(log, heads, rng)
    np.testing.assert_allclose(out["gamma"], out["psi_1"] - out["psi_2"], atol=1e-15)
    assert out["gamma"].std() > 0.005
    own = add_noise(log, parse_noise({"psi_1": {"sigma": 0.01}, "gamma": {"sigma": 0.001}},
                                     "t"), np.random.default_rng(0))
    assert own["gamma"].std() < 0.002
    # Channels not declared are left as they were; the same seed gives the same draw.
    assert (out["v_x_1"] == log["v_x_1"]).all()
    np.testing.assert_array_equal(out["psi_1"], add_noise(log, heads,
                                                          np.random.default_rng(0))["psi_1"])


def test_the_floor_of_white_velocity_noise_is_its_sigma():
    # v_y white with sigma on both units: eps_vy_i is the RMS of the noise,
    # sigma within 1/sqrt(2 n) ~ 1.6 % per draw (n = 2000), the mean of 16 draws
    # within 0.4 %: 1 % allows 2.5 standard errors. Nothing else is declared.
    log = straight_log(2000, u=1.0)
    noise = parse_noise({"v_y_1": {"sigma": 0.02}, "v_y_2": {"sigma": 0.02}}, "t")
    v = load_vehicle("gosar2022-unloaded")
    run = Run(log.frame.copy(), {"model": "kin"})
    table = summarise(floor_draws(log, run, noise, v))
    assert table.loc["eps_vy1", "floor"] == pytest.approx(0.02, rel=0.01)
    assert table.loc["eps_v", "floor"] == pytest.approx(0.04, rel=0.01)
    assert table.loc["eps_p", "floor"] == 0.0 and table.loc["eps_a", "floor"] == 0.0
    assert (table["n"].loc[["eps_vy1", "eps_p"]] == DRAWS).all()
    assert set(table.index) == set(FLOORED) and "J_steer" not in table.index
    again = summarise(floor_draws(log, run, noise, v))
    pd.testing.assert_frame_equal(table, again)


# ------------------------------------------------------------------ artic validate

@pytest.fixture(scope="module")
def twins(tmp_path_factory):
    """Each log through the default sensors, its noise-free twin, and the parquet files."""
    folder = tmp_path_factory.mktemp("twins")
    out = []
    for name in NAMES:
        m = next(x for x in MATRIX if x.name == name)
        # one truth run measured twice: through the sensors and without noise
        noisy, ideal = simulate_manoeuvre(m, 0, SensorModel(), twin=True)
        write_run(noisy, folder / f"{name}.parquet")
        out.append((noisy, ideal, folder / f"{name}.parquet"))
    return out


def test_without_declared_noise_validate_says_so_in_one_line(twins, tmp_path, capsys):
    assert main(["validate", str(twins[0][2]), "--models", "kin", "--no-recordings",
                 "--jobs", "1", "--out-dir", str(tmp_path / "out")]) == 0
    lines = [x for x in capsys.readouterr().out.splitlines() if x.startswith("Noise floor")]
    assert len(lines) == 1 and "no sensor noise declared" in lines[0]
    assert not (tmp_path / "out" / "noise_floor.csv").exists()


def test_a_bad_declaration_stops_validate_before_any_work(twins, tmp_path, capsys):
    bad = tmp_path / "noise.toml"
    bad.write_text("[noise]\nx_1 = { sigma = -0.01, tau = 5.0 }\n")
    out = tmp_path / "out"
    assert main(["validate", str(twins[0][2]), "--models", "kin", "--no-recordings",
                 "--noise", str(bad), "--out-dir", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"artic: error: {bad}: noise.x_1: sigma = -0.01; a sigma [m] is >= 0"]
    assert not (out / "metrics.csv").exists() and not (out / "runs").exists()


def test_the_printed_floor_is_what_the_noise_did_to_the_logs(twins, tmp_path, capsys):
    # The chain resamples the semitrailer unit's signals at its clock skew
    # (linear interpolation at a fraction f of a sample), which averages
    # neighbouring white samples: their standard deviation becomes
    # sigma sqrt((1 - f)^2 + f^2). The declaration says so, as a user's would
    # for a resampled channel. (The correlated noises barely change over 0.01 s.)
    skew = twins[0][0].meta["truth"]["trailer_clock_skew"]
    f = (skew / 0.01) % 1.0
    noise = tmp_path / "noise.toml"
    noise.write_text(declaration(SensorModel(), math.hypot(1.0 - f, f)))
    out = tmp_path / "out"
    logs = [str(p) for _, _, p in twins]
    assert main(["validate", *logs, "--models", "kin", "--no-recordings", "--jobs", "1",
                 "--noise", str(noise), "--out-dir", str(out)]) == 0
    text = capsys.readouterr().out
    assert f"Noise floor: the score a perfect model would get from the sensor noise declared in " \
           f"{noise}" in text
    assert "| eps_p [m] |" in text and "| eps_n [%] |" in text and "| eps_cover [m] |" in text
    floor = pd.read_csv(out / "noise_floor.csv")
    assert set(floor["log"]) == set(NAMES) and set(floor["model"]) == {"kin"}
    v = load_vehicle("gosar2022-unloaded")
    twin = {}
    for noisy, ideal, _ in twins:
        run = read_run(out / "runs" / f"{noisy.name}.kin.parquet")
        assert len(run.frame) == len(noisy.frame) == len(ideal.frame)
        assert np.allclose(noisy.frame["t"], ideal.frame["t"])
        twin[noisy.name] = (run_metrics(noisy.frame, ideal.frame)
                            | extra.of_run(noisy, Run(ideal.frame, ideal.meta), v))
    got = floor.set_index(["log", "criterion"])

    # White noise (velocities): each log's eps_v is the RMS of ~3800 samples a
    # unit, good to 1/sqrt(2 n) ~ 1.2 %, the floor's mean of 16 draws to 0.3 %:
    # 5 % is four standard errors of their difference.
    for name in NAMES:
        assert got.loc[(name, "eps_v"), "floor"] == pytest.approx(twin[name]["eps_v"], rel=0.05)

    # Correlated noise and a bias drawn once per log (positions, headings, the
    # gyros' bias): a log holds only a few correlation times, so one log is one
    # draw of a wide distribution. Over the four logs, the twins' mean must lie
    # within three standard errors of the floors' mean (the draws' spread sd per
    # log, one draw per log and 16 in the floor), plus 10 % of the floor for
    # the model standing in for the truck (KIN's runs, not the truth's).
    for c in ("eps_p", "eps_cover", "eps_a", "eps_gamma"):
        mean_floor = np.mean([got.loc[(n, c), "floor"] for n in NAMES])
        mean_twin = np.mean([twin[n][c] for n in NAMES])
        sd = np.sqrt(np.sum([got.loc[(n, c), "sd"] ** 2 for n in NAMES]) * (1 + 1 / DRAWS))
        sd /= len(NAMES)
        assert abs(mean_twin - mean_floor) <= 3.0 * sd + 0.1 * mean_floor, c
        # and every log's own value lies within the floor's spread of single draws.
        # Sixteen such checks, of scores made mostly by a bias drawn once per log:
        # |b| is half-normal, mean 0.8 sigma_b and sd 0.6 sigma_b, so a 2.7-sigma
        # draw (1 in 150) already sits 3.2 of its sd above its mean. Five sd
        # (|b| > 3.8 sigma_b, 1.4e-4 per check) keeps the family's false alarms
        # near 0.2 % and still fails a floor off by a factor of two.
        for n in NAMES:
            assert abs(twin[n][c] - got.loc[(n, c), "floor"]) <= 5.0 * got.loc[(n, c), "sd"], \
                (c, n)

    # eps_n: its velocity term is white noise over the run's mean |v_y|; the
    # floor takes that mean from KIN's run measured through the noise, the twin
    # from the truth's: KIN has no tyre slip, and its lateral velocity at the
    # sensors differs from the truth's by up to a tenth here, hence 15 %.
    for name in NAMES:
        assert got.loc[(name, "eps_n"), "floor"] == pytest.approx(twin[name]["eps_n"], rel=0.15)


def test_the_floor_is_the_same_for_the_same_inputs(twins):
    noisy, _, _ = twins[0]
    run = Run(noisy.frame.copy(), {"model": "kin"})
    noise = parse_noise({"x_1": {"sigma": 0.01, "tau": 5.0}}, "t")
    v = load_vehicle("gosar2022-unloaded")
    a = floor_draws(noisy, run, noise, v, draws=3)
    pd.testing.assert_frame_equal(a, floor_draws(noisy, run, noise, v, draws=3))
    other = floor_draws(noisy, dataclasses.replace(run, meta={"model": "stm"}), noise, v,
                        draws=3)
    assert not a["eps_y1"].equals(other["eps_y1"])  # another model: another draw


def test_a_channel_maps_noise_table_is_checked_with_the_map(tmp_path):
    from artic.validation.logs.channelmap import read_map

    path = tmp_path / "map.toml"
    head = ('[time]\ncolumn = "t"\nunit = "s"\n[channels]\nx_1 = { column = "X", unit = "m" }\n'
            'y_1 = { column = "Y", unit = "m" }\npsi_1 = { column = "h", unit = "rad" }\n'
            'gamma = { column = "g", unit = "deg" }\n')
    path.write_text(head + "[noise]\ngamma = { sigma = 0.1, unit = \"deg\" }\n")
    assert read_map(path).noise == {"gamma": ChannelNoise(math.radians(0.1))}
    path.write_text(head + "[noise]\nhitch = { sigma = 0.1 }\n")
    with pytest.raises(LogError, match=r"map.toml: noise.hitch: not a channel"):
        read_map(path)


def test_the_dock_errors_floor_is_a_magnitude():
    # A run that ends at the dock: the floor of the signed dock errors is the
    # mean magnitude of the end pose's noise. White lateral position noise of
    # sigma on the semitrailer's sensor: |N(0, sigma)| has mean sigma sqrt(2 / pi)
    # (0.8 sigma), and 16 draws give it to about 0.15 sigma; 0.4-1.2 sigma is
    # over two and a half standard errors either side.
    log = straight_log(1000, u=-1.0)
    log.meta["manoeuvre"] = "docking"
    noise = parse_noise({"y_2": {"sigma": 0.05}}, "t")
    v = load_vehicle("gosar2022-unloaded")
    draws = floor_draws(log, Run(log.frame.copy(), {"model": "kin"}), noise, v)
    assert (draws["dock_lat"] >= 0).all() and (draws["dock_lon"] < 1e-12).all()
    assert 0.4 * 0.05 < draws["dock_lat"].mean() < 1.2 * 0.05
