"""The yard truth: a skeleton, tyres and loop of its own, and physics that holds.

The independent truth (``validation/synthetic/yardtruth.py``, ``yardbuild.py``,
``yardtyres.py``) must share no code path with the plant under validation
(``artic.plant``, ``artic.mjcf.builder`` and its helpers): its import graph is
read here, and its behaviour checked against what a vehicle on its tyres does
at crawl speed, on a slope and in reverse.
"""

from __future__ import annotations

import ast
import importlib.util
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from artic.mjcf import load_vehicle
from artic.mjcf.interface import InitialState
from artic.validation.synthetic import truth as truth_mod
from artic.validation.synthetic import yardbuild, yardtyres
from artic.validation.synthetic.yardtruth import YardSetup, YardTruth
from tests.helpers import needs_compiled

YARD = "the yard truth's compiled loop (artic_yard_advance)"

TRUTH_MODULES = ("artic.validation.synthetic.yardtruth", "artic.validation.synthetic.yardbuild",
                 "artic.validation.synthetic.yardtyres", "artic.validation.synthetic.truth")
"""The modules that make the independent truth (its configuration, model, tyres, loop)."""

FORBIDDEN = ("artic.plant", "artic.mjcf.builder", "artic.mjcf.masses", "artic.mjcf.linkage",
             "artic.mjcf.naming")
"""The plant under validation and its builder's modules."""


def _imports(module: str) -> set[str]:
    """Every ``artic`` module a module's source imports, anywhere in it (functions too)."""
    spec = importlib.util.find_spec(module)
    tree = ast.parse(Path(spec.origin).read_text(encoding="utf-8"))
    package = module.rsplit(".", 1)[0] if not spec.origin.endswith("__init__.py") else module
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                base = ".".join(parts[:len(parts) - node.level + 1] + ([base] if base else []))
            out.add(base)
            for a in node.names:  # "from artic.validation.synthetic import yardtyres"
                sub = f"{base}.{a.name}"
                if importlib.util.find_spec(base) is not None and _is_module(sub):
                    out.add(sub)
    return {m for m in out if m == "artic" or m.startswith("artic.")}


def _is_module(name: str) -> bool:
    try:
        return importlib.util.find_spec(name) is not None
    except (ImportError, ValueError):
        return False


def _closure(roots) -> set[str]:
    seen, todo = set(), list(roots)
    while todo:
        m = todo.pop()
        if m in seen:
            continue
        seen.add(m)
        parts = m.split(".")
        todo.extend(".".join(parts[:i]) for i in range(1, len(parts)))  # packages run too
        todo.extend(_imports(m) - seen)
    return seen


def test_no_truth_module_imports_the_plant_or_its_builder():
    reached = _closure(TRUTH_MODULES)
    # the walk does reach what the truth uses: the vehicle file's data and its own modules
    assert {"artic.mjcf.vehicle", "artic.validation.synthetic.yardtyres"} <= reached
    bad = sorted(m for m in reached if any(m == f or m.startswith(f + ".") for f in FORBIDDEN))
    assert bad == [], f"the truth reaches the plant's code through {bad}"


@needs_compiled(YARD)
def test_a_running_truth_never_loads_the_plant():
    # Behaviour as well as source: a process that builds, resets and steps the
    # truth has not imported the plant or its builder.
    code = (
        "import sys\n"
        "from artic.mjcf import load_vehicle\n"
        "from artic.mjcf.interface import InitialState\n"
        "from artic.validation.synthetic.yardtruth import YardTruth\n"
        "t = YardTruth(load_vehicle('gosar2022-unloaded'))\n"
        "t.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=1.0))\n"
        "t.step(0.01, 0.05, 1.0, 0.0)\n"
        f"bad = [m for m in sys.modules if m.startswith({FORBIDDEN!r})]\n"
        "print(','.join(bad))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == ""


def test_the_presets_are_not_the_truths_mean():
    # Over many campaigns' truths, the mean of each drawn quantity sits at the
    # preset plus its stated offset, and so away from the preset: by more than
    # four standard errors of that mean (the draws are normal, 300 of them).
    n = 300
    for load in truth_mod.LOADS:
        p = load_vehicle(f"gosar2022-{load}")
        draws = [truth_mod.body_values(p, load, truth_mod.truth_configuration(s))
                 for s in range(n)]
        for key in ("m1", "J1", "a1", "h1", "L1c", "m2", "J2", "a2", "h2"):
            x = np.array([d[key] for d in draws])
            mean, se = x.mean(), x.std(ddof=1) / math.sqrt(n)
            preset = getattr(p, key)
            assert abs(mean - preset) > 4.0 * se, (load, key, mean, preset, se)
            name = key if key in truth_mod.OFFSETS else f"{key}.{load}"
            offset = truth_mod.OFFSETS[name][0]
            want = preset * (1.0 + offset) if key in ("m1", "J1", "m2", "J2") else preset + offset
            assert abs(mean - want) < 4.0 * se, (load, key, mean, want, se)
    tyres = np.array([[truth_mod.truth_configuration(s)["tyres"][k]
                       for k in ("pressure", "friction", "cornering")] for s in range(n)])
    assert np.all(np.abs(tyres.mean(axis=0) - 1.0) > 4.0 * tyres.std(axis=0) / math.sqrt(n))


def test_the_structural_truth_draws_as_before():
    # The independent truth's draws come after the structural truth's, which
    # the regression truths keep: seed 0's as they were (the release before).
    s = truth_mod.truth_configuration(0, "structural")
    assert "body" not in s and "tyres" not in s
    assert s["backlash"] == pytest.approx(0.041844386313451276, rel=1e-12)
    assert s["LKY"] == pytest.approx(1.0906374280601105, rel=1e-12)


def test_the_yard_tyres_come_from_the_published_pattern():
    t = yardtyres.yard_tyre("315/80R22.5")
    # Load index 156: 4000 kg; half of it is the nominal load at the rated pressure.
    assert t.fzn == pytest.approx(0.5 * 4000.0 * 9.81)
    assert t.r0 == pytest.approx(0.315 * 0.8 + 0.5 * 22.5 * 0.0254)
    # 16 % of the section height at the rated load
    assert t.cz * 0.16 * 0.252 == pytest.approx(4000.0 * 9.81)
    assert t.dfy0_1 == pytest.approx(7.4013 * t.fzn) and t.fym_1 == pytest.approx(0.75876 * t.fzn)
    twin = yardtyres.yard_tyre("315/80R22.5", twin=True)
    assert twin.fzn == pytest.approx(0.5 * 3350.0 * 9.81)
    low = yardtyres.yard_tyre("315/80R22.5", pressure=0.9, friction=0.95, cornering=0.9)
    assert low.fzn == pytest.approx(t.fzn * 0.9 ** 0.8)
    assert low.fym_1 == pytest.approx(0.75876 * low.fzn * 0.95)
    assert yardtyres.size_of("/x/artic-trailer-385-65R22.5.tir") == "385/65R22.5"
    with pytest.raises(ValueError, match="no tyre size"):
        yardtyres.size_of("mytyre.tir")


@pytest.fixture(scope="module")
def unloaded():
    return load_vehicle("gosar2022-unloaded")


def _run(truth: YardTruth, seconds: float, delta: float, u: float) -> np.ndarray:
    for _ in range(int(round(seconds / 0.01))):
        truth.step(0.01, delta, u, 0.0)
    return truth.observe()


@needs_compiled(YARD)
def test_a_steady_circle_at_crawl_speed_is_the_kinematic_one(unloaded):
    import dataclasses

    # With one semitrailer axle (its middle one) the combination is kinematically
    # determinate: at crawl speed the tyres barely slip, and the circle is the
    # geometry's. (A tri-axle group scrubs: its axles' opposed slips pull the
    # kingpin sideways and tighten the tractor's circle by some per cent.)
    v = dataclasses.replace(unloaded, axles=tuple(
        a for a in unloaded.axles if a.unit == 1 or a.name == "trailer-2"))
    delta, u = 0.25, 0.5  # [rad] the left (inner) wheel; [m/s]: lateral acceleration 0.02 m/s^2
    front = next(a for a in v.tractor_axles if a.steered)
    with YardTruth(v) as t:
        t.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=u))
        o = _run(t, 150.0, delta, u)  # 75 m of travel: past the articulation's transient
        left = t.data.qpos[t.model.jnt_qposadr[t.layout.steer_l]]
    # The column holds the left wheel at the demand but for the tyres' aligning
    # torque against its stiffness (a few hundredths of a degree at crawl speed).
    assert left == pytest.approx(delta, abs=math.radians(0.2))
    # The drive axle's centre turns on the radius the inner wheel's angle gives
    # (the knuckles stand on the axle's track), the kingpin ahead of it.
    R = v.L1 / math.tan(left) + 0.5 * front.track
    # 2 %: the tie rod's trapezoid is not exactly Ackermann's, so the two front
    # tyres slip against each other, and the twins scrub.
    assert o[5] == pytest.approx(u / R, rel=0.02)
    # The kingpin, L1c ahead of the drive axle, runs on Rk; the semitrailer's
    # axle, L2 behind it, on the radius at right angles to its heading: the
    # articulation is the angle between the two axles' radii.
    Rk = math.hypot(R, v.L1c)
    gamma = math.asin(v.L2 / Rk) - math.atan2(v.L1c, R)
    tol = math.radians(0.25)  # the tyres' slip at 0.02 m/s^2 (about 0.05 deg here)
    assert o[12] == pytest.approx(gamma, abs=tol), (math.degrees(o[12]), math.degrees(gamma))


@needs_compiled(YARD)
def test_standstill_holds_on_a_sloped_yard(unloaded):
    import dataclasses

    sloped = dataclasses.replace(unloaded, plant=dataclasses.replace(
        unloaded.plant, grade=math.atan(0.015), crossfall=math.atan(0.02)))
    with YardTruth(sloped, speed="pedals") as t:
        t.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=0.0))
        t.pedals = (0.0, 0.3)
        start = t.observe()
        end = _run(t, 20.0, 0.0, 0.0)
    # Dry-friction brakes: the combination holds on 1.5 % and 2 %; what moves is
    # its settling on the tyres' and suspensions' springs (millimetres).
    assert math.hypot(end[0] - start[0], end[1] - start[1]) < 0.01
    assert math.hypot(end[6] - start[6], end[7] - start[7]) < 0.01
    assert abs(end[3]) < 1e-3 and abs(end[9]) < 1e-3


@needs_compiled(YARD)
def test_reverse_is_sound(unloaded):
    # Reversing straight: the tyres' slips stay finite through standstill (no
    # division by the speed), the speed follows and the combination goes back.
    with YardTruth(unloaded) as t:
        t.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=0.0))
        for k in range(300):  # ramp to -1 m/s over 3 s
            t.step(0.01, 0.0, -k / 300.0, -1.0 / 3.0)
        o = _run(t, 10.0, 0.0, -1.0)
    assert o[3] == pytest.approx(-1.0, abs=0.01)
    assert o[0] < -10.0  # 11.5 m back
    # Reversing a semitrailer is unstable, but straight and from rest its
    # articulation only grows from the sensors' mounting and the slope-free
    # yard's nothing: within a tenth of a degree after 11 m.
    assert abs(o[12]) < math.radians(0.1)
    assert np.all(np.isfinite(t.z))


@needs_compiled(YARD)
def test_the_full_state_continues_a_run_bit_for_bit(unloaded):
    setup = YardSetup(play=math.radians(2.0))
    with YardTruth(unloaded, setup) as a, YardTruth(unloaded, setup) as b:
        a.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=1.0))
        _run(a, 1.0, 0.1, 1.0)
        saved = a.full_state()
        _run(a, 1.0, -0.1, 0.5)
        b.reset(InitialState(5.0, 5.0, 1.0, 0.2, u1=0.0))  # elsewhere
        b.set_full_state(saved)
        _run(b, 1.0, -0.1, 0.5)
        assert np.array_equal(a.observe(), b.observe())
        assert np.array_equal(a.full_state(), b.full_state())
    with pytest.raises(ValueError, match="full state"):
        a.set_full_state(saved[:-1])


@needs_compiled(YARD)
def test_its_mechanisms_are_in_the_model(unloaded):
    with YardTruth(unloaded) as t:
        m = t.model
        names = {m.joint(i).name for i in range(m.njnt)}
        assert {"frame_torsion", "cab_roll", "cab_pitch", "fifth_roll", "fifth_pitch",
                "kingpin"} <= names
        # one roll-steer equality per axle, the plant's tie-rod equality nowhere
        assert m.neq == len(unloaded.axles)
        assert m.nnumeric == 0 and m.nu == 0  # no block for anyone's callback, no servo
        # the front frame twists against the rear under a crossfall's load
        assert m.jnt_stiffness[m.joint("frame_torsion").id] == pytest.approx(
            yardbuild.FRAME_TORSION)


@needs_compiled(YARD)
def test_the_fifth_wheel_rolls_free_within_its_lash(unloaded):
    # The plate's bushes carry nothing until the lash is taken up, then their
    # stiffness: the roll torque the loop applies at the fifth wheel's roll joint.
    lash, k = yardbuild.FIFTH_WHEEL_LASH, yardbuild.FIFTH_WHEEL_ROLL
    with YardTruth(unloaded) as t:
        dof = t.layout.fifth_roll
        qa = t.model.jnt_qposadr[t.model.dof_jntid[dof]]
        torques = []
        for angle in (0.3 * lash, 0.5 * lash + 1e-3):
            t.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=0.0))
            t.data.qpos[qa] = angle
            t.data.qvel[:] = 0.0
            t._advance(1)  # one step: the torque at that angle, the plate at rest
            torques.append(t.fifth_wheel_torque)
    # inside the lash: nothing but the smoothing of its edge (2 % of it wide)
    assert abs(torques[0]) < 1e-3 * k * lash
    # past it by 1 mrad: the bushes' stiffness (the edge's smoothing and one
    # step's motion change it by a few per cent)
    assert torques[1] == pytest.approx(-k * 1e-3, rel=0.1)


@needs_compiled(YARD)
def test_the_follower_asks_no_more_than_the_drive_gives(unloaded):
    # The floor's follower under a demand far past the drive (5 m/s^2 in reverse):
    # its force is held at what the driven tyres carry without spinning up and its
    # integral stops, so the driven wheels roll with the ground instead of
    # spinning up without end (a noisy log's speed once asked for that).
    from artic.validation.synthetic.yardtruth import FOLLOW_TRACTION

    loads = yardbuild.static_loads(unloaded)
    limit = FOLLOW_TRACTION * sum(loads[a.name] for a in unloaded.axles if a.driven)
    a_max = limit / (unloaded.m1 + unloaded.m2)
    with YardTruth(unloaded) as t:
        t.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=0.0))
        for k in range(100):
            t.step(0.01, 0.0, -0.05 * k, -5.0)
        v = t.observe()[3]
        spin = t.data.qvel[t._spin] * np.array([t.tyres[e["axle"]].r0 for e in t.layout.ends])
    # 1 s at the limit, less the rolling resistance (0.06 m/s^2) and the start
    assert -a_max * 1.02 < v < -a_max * 0.85, (v, a_max)
    # every wheel rolls within the tyres' traction slip of the ground (a tenth)
    assert np.max(np.abs(spin - v)) < 0.1 * abs(v)


@needs_compiled(YARD)
def test_its_step_converges(unloaded):
    # The yard truth at its 2.5 ms against itself at 1 ms: a ramp of the steering
    # to 0.3 rad while pulling off to 1.4 m/s, 10 s. Its modes lie well inside
    # the explicit scheme's region (docs/design/truth.md); what is left is the
    # first-order error of the semi-implicit step: 1.0 mm, 4e-4 deg, 5e-8 rad/s here.
    out = []
    for h in (yardbuild.TIMESTEP, 1e-3):
        with YardTruth(unloaded, YardSetup(play=math.radians(2.0)), timestep=h) as t:
            t.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=0.0))
            for k in range(1000):
                t.step(0.01, min(0.3, 0.001 * k), min(1.4, 0.005 * k), 0.5 if k < 280 else 0.0)
            out.append(t.observe())
    a, b = out
    assert math.hypot(a[6] - b[6], a[7] - b[7]) < 0.01  # [m] the campaign's targets:
    assert abs(a[12] - b[12]) < math.radians(0.05)  # 1 cm, 0.05 deg,
    assert abs(a[5] - b[5]) < 1e-3  # 1e-3 rad/s


def test_every_body_gets_inertias_a_body_can_have():
    # A frame half whose yaw budget is small must not get a roll inertia above
    # its pitch and yaw inertias' sum (MuJoCo refuses it: a drawn truck did).
    from artic.validation.synthetic.yardbuild import _box

    a, b, c = _box(4000.0, 4000.0 * 0.45 ** 2, 300.0, 300.0)
    assert a <= b + c and b <= a + c and c <= a + b
    assert (a, b, c) == (600.0, 300.0, 300.0)  # roll lowered to the sum, the rest kept
    assert _box(10.0, 1.0, 2.0, 2.5) == [1.0, 2.0, 2.5]  # a valid body is unchanged
