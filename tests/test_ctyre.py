"""The compiled tyre callback against the numpy reference, and what it makes possible."""

from __future__ import annotations

import threading
from pathlib import Path

import mujoco
import numpy as np
import pytest

from artic.mjcf.interface import InitialState
from artic.plant import Plant, callback, ctyre
from artic.plant.tyre import TyreParams, deflection_rates, rolling_resistance, transient_forces
from tests.helpers import needs_compiled
from tests.shared_data import REFERENCE_TYRE, needs

TRAILER_TYRE = "artic-trailer-385-65R22.5.tir"


# The compiled callback against its reference: nothing to compare without it.
pytestmark = needs_compiled("the compiled tyre callback")


@pytest.fixture(scope="module", autouse=True)
def compiled():
    # CI installs with a C compiler, so the extension must be there: its absence
    # is a failed build, not a reason to skip (needs_compiled skips only where
    # artic runs without its compiled parts on purpose).
    assert ctyre.library() is not None, ctyre.unavailable_reason()


def random_states(n: int, seed: int = 0) -> dict[str, np.ndarray]:
    """Wheel states over forward, reverse, standstill and large slip."""
    rng = np.random.default_rng(seed)
    Vx = rng.uniform(-6.0, 6.0, n)
    Vx[: n // 5] = 0.0  # standstill
    Vx[n // 5: n // 4] = rng.uniform(-0.5, 0.5, n // 4 - n // 5)  # below VXLOW
    return {
        "Fz": rng.uniform(-2e3, 60e3, n),  # in the air, light and overloaded
        "Vx": Vx,
        "Vsx": rng.normal(0.0, 1.0, n),
        "Vy": rng.normal(0.0, 1.5, n),
        "omega_z": rng.normal(0.0, 0.5, n),  # the wheel's yaw rate, steering included
        "u": rng.normal(0.0, 0.05, n),  # kappa up to about +-0.3 at 20 kN
        "v": rng.normal(0.0, 0.3, n),  # alpha up to about +-60 deg
        "phi": rng.normal(0.0, 0.1, n),  # twist past its sliding angle
    }


@pytest.mark.parametrize("moments", [True, False])
@pytest.mark.parametrize("which", ["artic", "trailer",
                                   pytest.param("shared", marks=needs(REFERENCE_TYRE))])
def test_compiled_forces_equal_the_numpy_reference(which, moments, unloaded):
    from importlib import resources

    path = {"artic": unloaded.tyre_file, "shared": REFERENCE_TYRE,
            "trailer": resources.files("artic.mjcf") / "tyres"
            / "artic-trailer-385-65R22.5.tir"}[which]
    p = TyreParams.from_tir(path)
    s = random_states(10_000)
    args = [s[k] for k in ("Fz", "Vx", "Vsx", "Vy", "omega_z", "u", "v", "phi")]
    c = ctyre.evaluate(p, *args, moments=moments)
    Fx, Fy, Mz = transient_forces(p, *args, moments=moments)
    du, dv, dphi = deflection_rates(p, *args)
    My = rolling_resistance(p, s["Fz"], s["Vx"], Fx)
    # Both evaluate the same formulas in double precision; the C code replaces
    # cos(atan x) and sin(2 atan x) by their algebraic forms, so they differ by
    # rounding only. 1e-9 relative, on a floor of 1 N (1 N m, 1 um/s) so that
    # forces that vanish at zero load or slip are compared absolutely.
    for name, ref, got in (("Fx", Fx, c.Fx), ("Fy", Fy, c.Fy), ("Mz", Mz, c.Mz),
                           ("My", My, c.My), ("du", du, c.du), ("dv", dv, c.dv),
                           ("dphi", dphi, c.dphi)):
        floor = 1e-6 if name in ("du", "dv", "dphi") else 1.0
        err = np.abs(got - ref) / np.maximum(np.abs(ref), floor)
        assert np.all(np.isfinite(got)), name
        assert err.max() < 1e-9, f"{name}: worst relative error {err.max():.2e}"
    if moments:
        assert np.abs(Mz).max() > 1e3  # the moments are there to compare
    # The sample reaches large slip and both directions, as it claims.
    alpha = np.arctan(s["v"] / p.sigma_alpha(np.maximum(s["Fz"], p.FZMIN)))
    assert np.abs(alpha).max() > 1.0 and (s["Vx"] < -1).any() and (s["Vx"] == 0).sum() >= 2000


def trajectory(vehicle, backend, seconds=10.0, tyre_files=None):
    with Plant(vehicle, backend=backend, tyre_files=tyre_files) as p:
        p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=1.5))
        out = []
        for k in range(int(seconds / 0.01)):
            # forward for 0.5 s, braking at 2 m/s^2 through standstill (at 1.25 s),
            # into reverse at 1 m/s (from 1.75 s); the steering to both sides
            t = k * 0.01
            u, u_dot = (1.5, 0.0) if t < 0.5 else (max(1.5 - 2.0 * (t - 0.5), -1.0), -2.0)
            p.step(0.01, 0.2 * np.sin(2.0 * t), u, u_dot if u > -1.0 else 0.0)
            out.append(p.observe())
        return np.array(out)


@pytest.mark.parametrize("moments", [False, True])
def test_plant_trajectories_agree_between_backends(unloaded, moments):
    # Same equations, same integrator: over 2.5 s, forward, through a stop and
    # into reverse, rounding differences must stay at rounding level. 1e-9 m and
    # rad is six orders above double rounding and far below any physical effect.
    # The numpy backend steps about 20 times slower than the compiled one, so the
    # run is as short as covers every regime a wheel meets (rolling both ways,
    # standstill, the slip transients of a hard stop, steering both ways); the
    # formulas themselves are compared point by point above, at 10 000 states.
    # With the moments, the semitrailer runs on another tyre file, so each
    # wheel end's coefficient set is looked up through its index in the block.
    import dataclasses

    v = dataclasses.replace(unloaded, plant=dataclasses.replace(unloaded.plant,
                                                                tyre_moments=moments))
    files = {i: TRAILER_TYRE for i, a in enumerate(v.axles) if a.unit == 2} if moments else None
    a, b = (trajectory(v, backend, 2.5, tyre_files=files) for backend in ("compiled", "python"))
    assert np.abs(a - b).max() < 1e-9
    assert a[:, 3].min() < -0.5 and a[:, 3].max() > 1.0  # both directions reached
    assert np.abs(a[:, 3]).min() < 0.05  # through standstill


def test_native_callback_installed_and_restored(unloaded):
    assert callback.active() == 0
    with Plant(unloaded, backend="compiled"):
        assert not callback.python_installed()
        with Plant(unloaded, backend="python"):
            assert callback.python_installed()  # the dispatcher serves both
        # ... and stays while a plant is open: from Python back to C is the change a
        # step in flight on another thread does not survive (test_callback_threads).
        assert callback.python_installed()
    assert mujoco.get_mjcb_passive() is None
    with Plant(unloaded, backend="compiled"):  # the next compiled plant alone: C again
        assert not callback.python_installed()


def test_models_without_the_block_get_no_force(unloaded):
    m = mujoco.MjModel.from_xml_string(
        "<mujoco><worldbody><body><freejoint/><geom size='1'/></body></worldbody></mujoco>")
    d = mujoco.MjData(m)
    with Plant(unloaded, backend="compiled"):
        mujoco.mj_step(m, d)
    assert np.all(d.qfrc_passive == 0.0)


def test_plants_on_threads_equal_serial(unloaded, loaded):
    # The C callback runs without the GIL and keeps no global state, so plants
    # step on threads; each result equals its serial run bit for bit.
    serial = [trajectory(v, "compiled", 3.0) for v in (unloaded, loaded)]
    out: list = [None, None]

    def work(i, v):
        out[i] = trajectory(v, "compiled", 3.0)

    threads = [threading.Thread(target=work, args=(i, v))
               for i, v in enumerate((unloaded, loaded))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for a, b in zip(serial, out, strict=True):
        np.testing.assert_array_equal(a, b)


def test_tyre_files_per_axle(unloaded):
    # The plant takes a tyre file per axle index; the others keep the vehicle's.
    from artic.mjcf.vehicle import VehicleFileError

    trailer = [i for i, a in enumerate(unloaded.axles) if a.unit == 2]
    with Plant(unloaded, tyre_files={i: TRAILER_TYRE for i in trailer}) as p:
        per_wheel = [t.path for t in p.wheel_tyres]
        assert len(p.tyres) == 2 and len(per_wheel) == p.n_wheels
        for i, a in enumerate(unloaded.axles):
            own = TRAILER_TYRE if i in trailer else Path(unloaded.tyre_file).name
            assert [Path(f).name for f in per_wheel[2 * i:2 * i + 2]] == [own, own], a.name
        # The block holds both sets and each wheel's index into them.
        blk = p.model.numeric_data
        nh, npar = len(ctyre.HEADER_FIELDS), len(ctyre.param_names())
        wheels = blk[nh + 2 * npar:].reshape(p.n_wheels, len(ctyre.WHEEL_FIELDS))
        sets = wheels[:, ctyre.WHEEL_FIELDS.index("tyre_set")].astype(int)
        r0 = blk[nh + sets * npar + ctyre.param_names().index("UNLOADED_RADIUS")]
        np.testing.assert_array_equal(r0, [t.UNLOADED_RADIUS for t in p.wheel_tyres])
        assert p.wheel_tyres[-1].UNLOADED_RADIUS != p.wheel_tyres[0].UNLOADED_RADIUS
    with Plant(unloaded) as p:  # by default, the vehicle's one tyre everywhere
        assert {t.path for t in p.wheel_tyres} == {p.tyre.path} and len(p.tyres) == 1
    with pytest.raises(ValueError, match="tyre_files: axle 99 does not exist"):
        Plant(unloaded, tyre_files={99: TRAILER_TYRE})
    with pytest.raises(VehicleFileError, match=r"tyre_files\[0\].*'nope.tir'"):
        Plant(unloaded, tyre_files={0: "nope.tir"})


def test_a_vertical_hub_axis_gets_no_force_in_either_backend(unloaded):
    # A wheel knocked onto its side has no heading on the ground: the C code
    # guards that division and gives the wheel no force; the numpy reference
    # must do the same (it divided by zero before), and the others go on.
    out = {}
    for backend in ("compiled", "python"):
        with Plant(unloaded, backend=backend) as p:
            p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=2.0))
            m, d = p.model, p.data
            d.site_xmat[p._hub[0]] = [0, 0, 1, 0, 1, 0, -1, 0, 0]  # x-axis straight down
            d.ctrl[p._tread_u[0]] = d.ctrl[p._tread_v[0]] = d.ctrl[p._tread_w[0]] = 1.0
            d.qfrc_passive[:] = 0.0
            if backend == "compiled":
                ctyre.call_passive(m, d)
            else:
                p._passive(m, d)
            out[backend] = (p.last_forces.copy(), d.qfrc_passive.copy(),
                            d.ctrl[[p._tread_u[0], p._tread_v[0], p._tread_w[0]]].copy())
    for F, qfrc, rates in out.values():
        assert np.all(np.isfinite(qfrc)) and np.all(F[0] == 0.0) and np.all(rates == 0.0)
        assert np.all(F[1:, 2] > 1e3)  # the other wheels carry the truck
    np.testing.assert_allclose(out["compiled"][0], out["python"][0], rtol=1e-9, atol=1e-6)
    np.testing.assert_allclose(out["compiled"][1], out["python"][1], rtol=1e-9, atol=1e-6)


def test_generalised_forces_of_a_turning_plant_equal_mujocos_apply_ft(unloaded):
    # The C callback sums each wheel's force and moment along the wheel's dof
    # chain itself; the numpy reference hands them to MuJoCo's mj_applyFT.
    # In a turn under way (every wheel loaded, slipping, with aligning and
    # rolling moments) both must give the same qfrc_passive: the tyre forces
    # agree to about 1e-12 relative (test above), the chain sum is exact.
    with Plant(unloaded, backend="compiled") as p:
        p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=2.0))
        for _ in range(150):
            p.step(0.01, 0.25, 2.0, 0.0)
        spec = mujoco.mjtState.mjSTATE_PHYSICS  # qpos, qvel, act: the numpy model has no userdata
        state = np.empty(mujoco.mj_stateSize(p.model, spec))
        mujoco.mj_getState(p.model, p.data, state, spec)
        m, d = p.model, p.data
        mujoco.mj_forward(m, d)
        d.qfrc_passive[:] = 0.0
        ctyre.call_passive(m, d)
        qfrc_c = d.qfrc_passive.copy()
    with Plant(unloaded, backend="python") as p:
        m, d = p.model, p.data
        mujoco.mj_setState(m, d, state, spec)
        mujoco.mj_forward(m, d)
        d.qfrc_passive[:] = 0.0
        p._passive(m, d)
        qfrc_np = d.qfrc_passive.copy()
    assert np.abs(qfrc_c).max() > 1e4  # the wheels carry the truck
    # Nearly every dof feels the tyres; the steer and spin dofs see moments only.
    assert np.count_nonzero(np.abs(qfrc_c) > 1e-3) > m.nv // 2
    np.testing.assert_allclose(qfrc_c, qfrc_np, rtol=1e-9, atol=1e-6)


def test_a_block_edited_after_use_is_refused_at_once_and_taken_back_when_restored(unloaded):
    # The callback remembers, per thread, the last block it found valid. An
    # edit in place that is not sealed (a tyre coefficient here) must miss
    # that memory and be refused at the very next evaluation, as a block
    # damaged from the start is; the block as it was must be taken again.
    with Plant(unloaded, backend="compiled") as p:
        m, d = p.model, p.data
        p.reset(InitialState(0.0, 0.0, 0.0, 0.1, u1=2.0))
        mujoco.mj_forward(m, d)
        tyres = d.qfrc_passive.copy()  # the block was checked, and remembered
        saved = mujoco.get_mjcb_passive()
        mujoco.set_mjcb_passive(None)
        try:
            mujoco.mj_forward(m, d)
            without = d.qfrc_passive.copy()  # MuJoCo's own springs and dampers
        finally:
            mujoco.set_mjcb_passive(saved)
        assert np.abs(tyres - without).max() > 1e3  # the tyres carry the truck
        k = len(ctyre.HEADER_FIELDS) + ctyre.param_names().index("PDY1")
        before = float(m.numeric_data[k])
        m.numeric_data[k] = before * 1.01
        mujoco.mj_forward(m, d)
        np.testing.assert_array_equal(d.qfrc_passive, without)
        m.numeric_data[k] = before
        mujoco.mj_forward(m, d)
        np.testing.assert_array_equal(d.qfrc_passive, tyres)
