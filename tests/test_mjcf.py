"""The MJCF generator: structure, masses, linkage, XML round trip."""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pytest

from artic.mjcf import load_vehicle
from artic.mjcf import naming as nm
from artic.mjcf.builder import build_model, linkage, to_xml
from artic.mjcf.linkage import Trapezoid, centre_angle
from artic.mjcf.vehicle import G
from artic.validation.cli.commands import main
from tests.helpers import PRESETS


@pytest.fixture(scope="module", params=PRESETS)
def built(request):
    v = load_vehicle(request.param)
    m = build_model(v).compile()
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    return v, m, d


def unit_bodies(m, unit):
    trailer = m.body(nm.TRAILER).id
    ids = []
    for b in range(1, m.nbody):
        chain, p = [], b
        while p != 0:
            chain.append(p)
            p = m.body_parentid[p]
        if m.body(nm.DOCK).id in chain if nm.DOCK in [m.body(i).name for i in range(m.nbody)] \
                else False:
            continue
        if (trailer in chain) == (unit == 2) and m.body(chain[-1]).name == nm.TRACTOR:
            ids.append(b)
    return ids


def test_axles_in_the_xml(built):
    v, m, _ = built
    root = ET.fromstring(to_xml(v))
    axles = [b for b in root.iter("body") if b.get("name", "").startswith("axle.")]
    assert len(axles) == len(v.axles) == (6 if v.name == "six-axle" else 5)
    spins = [j for j in root.iter("joint") if j.get("name", "").startswith("spin.")]
    assert len(spins) == 2 * len(v.axles)


def test_xml_loads_unchanged(built):
    v, m, _ = built
    m2 = mujoco.MjModel.from_xml_string(to_xml(v))
    for attr in ("nbody", "njnt", "nq", "nv", "nu", "na", "neq"):
        assert getattr(m2, attr) == getattr(m, attr), attr
    # MuJoCo writes 6 significant digits: the reloaded numbers agree to that.
    np.testing.assert_allclose(m2.body_mass, m.body_mass, rtol=1e-5)
    np.testing.assert_allclose(m2.body_inertia, m.body_inertia, rtol=1e-5)


def test_unit_mass_centre_and_yaw_inertia_match_file(built):
    # Composite of each unit's bodies at rest: mass, centre of gravity and
    # yaw inertia about it are the file's (rounding only).
    v, m, d = built
    for unit, mass, x_g, h, J in ((1, v.m1, v.b1, v.h1, v.J1),
                                  (2, v.m2, v.L1c - v.a2, v.h2, v.J2)):
        ids = unit_bodies(m, unit)
        mb = m.body_mass[ids]
        pos = d.xipos[ids]
        assert mb.sum() == pytest.approx(mass, rel=1e-12)
        com = (mb[:, None] * pos).sum(axis=0) / mb.sum()
        assert com[0] == pytest.approx(x_g, abs=1e-9)
        assert com[2] == pytest.approx(h, abs=1e-9)
        Izz = sum(m.body_inertia[b][2] for b in ids)  # frames are aligned at rest
        Izz += (mb * ((pos[:, 0] - com[0]) ** 2 + (pos[:, 1] - com[1]) ** 2)).sum()
        assert Izz == pytest.approx(J, rel=1e-9)


def test_springs_carry_the_static_loads(built):
    # At rest every suspension spring pushes the axle down with the sprung
    # part of its static load: load minus unsprung weight.
    v, m, d = built
    for a, fz in zip(v.axles, v.static_loads, strict=True):
        j = m.joint(nm.suspension(a.name))
        springref = m.qpos_spring[m.jnt_qposadr[j.id]]
        force = -j.stiffness[0] * (0.0 - springref)
        assert force == pytest.approx(-(fz - a.unsprung_mass * G), rel=1e-12)


def test_sensor_sites(built):
    v, m, d = built
    s1 = d.site(nm.sensor(1)).xpos
    s2 = d.site(nm.sensor(2)).xpos
    assert s1[:2] == pytest.approx(v.sensor1[:2])
    assert s2[:2] == pytest.approx(v.sensor2_from_drive_axle[:2])


def test_linkage_is_ackermann_like_and_asymmetric():
    trap = Trapezoid(track=2.05, wheelbase=3.8, arm=0.25)
    a = math.radians(20.0)
    # Left turn: the left wheel is inside and turns more.
    assert 0 < trap.right_angle(a) < a
    assert trap.right_angle(-a) < -a
    # The centre angle is lower for left turns than right: eq. (3)'s q > 0.
    c_left = float(centre_angle(np.array(a), np.array(trap.right_angle(a))))
    c_right = float(centre_angle(np.array(-a), np.array(trap.right_angle(-a))))
    q_wheel = (abs(c_right) - abs(c_left)) / (2 * a * a)  # per rad of wheel angle
    q = q_wheel / 21.0  # per rad of steering wheel, i_s = 21
    # Seed notes section 4: a trapezoid gives q of about 0.01 /rad.
    assert 0.004 < q < 0.02


def test_trapezoid_keeps_the_rod_length_on_the_assembled_branch():
    trap = Trapezoid(track=2.05, wheelbase=3.8, arm=0.25)
    # This trapezoid locks near -0.72 rad, where the right wheel races ahead.
    d = np.linspace(-0.6, 0.75, 136)
    r = trap.right_angles(d)
    gaps = [np.linalg.norm(np.subtract(*trap._tips(a, b))) for a, b in zip(d, r, strict=True)]
    # The closed-form crossing of two circles: the rod length holds to round-off.
    assert np.max(np.abs(np.array(gaps) - trap.rod)) < 1e-12
    # The assembled branch: straight ahead is straight ahead, and the right
    # wheel follows the left smoothly (the other branch is a jump of ~2 beta).
    assert trap.right_angle(0.0) == pytest.approx(0.0, abs=1e-14)
    assert np.max(np.abs(np.diff(r))) < 2.0 * (d[1] - d[0])
    with pytest.raises(ValueError, match="cannot reach"):
        Trapezoid(track=2.0, wheelbase=3.6, arm=0.3).right_angle(-1.2)


@pytest.mark.parametrize("name", PRESETS)
def test_polynomial_fits_the_trapezoid(name):
    v = load_vehicle(name)
    trap, poly, (lo, hi) = linkage(v)
    d = np.linspace(lo, hi, 200)
    exact = trap.right_angles(d)
    err = np.abs(np.polynomial.polynomial.polyval(d, poly) - exact)
    # The bounds the builder documents: a quartic weighted to yard angles.
    assert np.max(err[np.abs(d) < math.radians(20)]) < math.radians(0.16)
    assert np.max(err[np.abs(d) < math.radians(30)]) < math.radians(0.6)
    assert np.max(err) < math.radians(0.95)
    assert poly[0] == 0.0  # no toe when the left wheel points straight ahead
    # The servo's range reaches exactly delta_max at the axle centre, through
    # the linkage the model has.
    c = centre_angle(np.array([lo, hi]), np.polynomial.polynomial.polyval([lo, hi], poly))
    assert c == pytest.approx([-v.steering.delta_max, v.steering.delta_max], abs=1e-9)


def test_cli_writes_mjcf(tmp_path, capsys):
    out = tmp_path / "m.xml"
    assert main(["mjcf", "--vehicle", "six-axle", "-o", str(out)]) == 0
    assert "6 axles" in capsys.readouterr().out
    m = mujoco.MjModel.from_xml_path(str(out))
    assert m.body(nm.DOCK).id > 0
    assert main(["mjcf", "--vehicle", "six-axle", "--no-scene", "-o", str(out)]) == 0
    with pytest.raises(KeyError):
        mujoco.MjModel.from_xml_path(str(out)).body(nm.DOCK)


def test_wrap_angle_scalar_path_equals_the_array_path_to_the_bit():
    from artic.mjcf.interface import wrap_angle

    rng = np.random.default_rng(1)
    xs = np.concatenate([rng.normal(0.0, 10.0, 20000), rng.normal(0.0, 1e-3, 1000),
                         [0.0, -0.0, math.pi, -math.pi, 3 * math.pi, -3 * math.pi,
                          2 * math.pi, -2 * math.pi, 1e300, -1e-300]])
    scalar = np.array([wrap_angle(float(x)) for x in xs])
    numpy64 = np.array([wrap_angle(x) for x in xs])  # numpy.float64 takes the scalar path too
    array = wrap_angle(xs)
    assert np.array_equal(scalar, array) and np.array_equal(numpy64, array)
    assert np.array_equal(np.signbit(scalar), np.signbit(array))
    # (-pi, pi]: pi stays, -pi becomes pi.
    assert wrap_angle(math.pi) == math.pi and wrap_angle(-math.pi) == math.pi
    assert np.all((array > -math.pi) & (array <= math.pi))


def test_a_yaw_inertia_the_bodies_cannot_carry_names_both_parts():
    # The chassis gets what is left of the unit's yaw inertia once the axles' bodies and the
    # chassis's own offset from the unit's centre of gravity are counted. A file whose J1 is
    # below that sum is refused, naming both parts and their sum (it named the axles alone
    # and called 10 309 "more than" 11 126, for a truck drawn by the yard truth).
    from dataclasses import replace

    from artic.mjcf.masses import layout
    from artic.mjcf.schema import VehicleFileError

    v = load_vehicle("gosar2022-unloaded")
    with pytest.raises(VehicleFileError) as err:
        layout(replace(v, J1=1.0))
    text = str(err.value)
    assert "key 'tractor.J1'" in text and "chassis's offset from the centre of gravity" in text
    axles = float(re.search(r"axles \((\d+) kg m\^2\)", text).group(1))
    offset = float(re.search(r"gravity \((\d+)\)", text).group(1))
    need = float(re.search(r"need (\d+) kg m\^2", text).group(1))
    assert abs(axles + offset - need) <= 1.0 and need > 1.0  # rounding to whole kg m^2
