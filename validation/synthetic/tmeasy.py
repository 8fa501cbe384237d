"""The truth's tyres: TMeasy, fitted to a ``.tir`` file's steady-state curves.

TMeasy ("Tire Model Made Easy") is G. Rill's semi-physical tyre model, from
"Road Vehicle Dynamics: Fundamentals and Modeling" (CRC Press, 2011), chapter
3: another family than the plant's Magic Formula (PAC2002, :mod:`artic.plant.tyre`).
Where PAC2002 fits each curve with a sine of an arctangent, and combines slips
by weighting functions, TMeasy describes each curve by five numbers a
tyre test reads off: the slope at zero slip ``dF0``, the peak ``(sM, FM)`` and
the start of sliding ``(sS, FS)``; between them a rational function and a
cubic. Combined slip is one generalised characteristic over the normalised
slips; load dependence is quadratic through the values at the nominal load
``Fz_N`` and at ``2 Fz_N``; the deflections of the tyre are first-order
states of a spring and damper (:mod:`_truth_c.c <artic.validation.synthetic.truthc>`
has the equations and cites the sections). It is evaluated only in C.

:func:`fit` makes a TMeasy tyre of a ``.tir`` file (the shipped truck and
trailer tyres, with the truth's scaling applied), from the file's own
steady-state curves (:func:`artic.plant.tyre.steady_state`, as
``artic tyre curves`` plots them), by least squares over loads of
:data:`FIT_LOADS` times the nominal load:

- pure longitudinal slip, kappa within +-0.3, as TMeasy's slip
  ``s_x = kappa / (1 + kappa)`` (TMeasy divides by the wheel's rolling speed,
  PAC2002 by the travel speed);
- pure lateral slip, slip angles to 60 deg (both evaluate at ``tan(alpha)``);
- the aligning torque to 20 deg, small angles weighted more: TMeasy's
  pneumatic trail is the patch length ``L = 2 sqrt(r0 Fz / c_z)`` times a
  function of ``s_y``.

What no steady curve gives comes from the file's own transient and stated
physics: the longitudinal and lateral tyre stiffnesses ``c_x, c_y`` are the
slip stiffness over the relaxation length at the nominal load (the file's
``Kx / sigma_kappa`` and ``Ky / sigma_alpha``), so the relaxation lengths
agree there (TMeasy's relaxation length is ``dF0 / c``, and so varies with the
load as ``dF0`` does); each damper is :data:`DAMPING_TIME` times its spring;
the torsional stiffness makes the bore torque slide at :data:`BORE_TWIST` at
the nominal load. The tolerances the fit meets are :data:`TOLERANCE`; the
tests check them.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from pathlib import Path

import numpy as np

from artic.mjcf.tir import read_tir
from artic.plant.plant import scaled
from artic.plant.tyre import TyreParams, steady_state
from artic.validation.synthetic import truthc

FIT_LOADS = (0.2, 0.35, 0.5, 0.75, 1.0, 1.25, 1.5)
"""Loads of the fit, times the file's nominal load: the wheel loads of the
campaign's vehicles, empty semitrailer to laden front axle, lie in it."""

KAPPA_MAX = 0.3
"""Longitudinal slip of the fit [-]: ``artic tyre curves``' range."""

ALPHA_MAX_DEG = 60.0
"""Slip angle of the force fit [deg]: past the lateral peak (near 20 deg for the
shipped tyres) far into sliding, where a tyre steered at standstill works."""

MZ_ALPHA_MAX_DEG = 20.0
"""Slip angle of the aligning-torque fit [deg]: ``artic tyre curves``' range,
which holds the torque's peak (3-5 deg) and its change of sign (about 15 deg)."""

TOLERANCE = {"Fx": 0.07, "Fy": 0.03, "slope": 0.03, "Mz": 0.3, "Mz_slope": 0.15}
"""What the fit meets at every load of :data:`FIT_LOADS` (``tests/test_tmeasy.py``):

- ``Fx``, ``Fy``: the forces within 7 % and 3 % of the PAC2002 curve's peak at
  that load. Longitudinally the two families differ in the slip itself:
  TMeasy's characteristic is odd in ``s_x``, PAC2002's in kappa, and
  ``s_x = kappa / (1 + kappa)`` is not odd;
- ``slope``: the slip stiffnesses at zero slip within 3 % (TMeasy's quadratic
  load law against PAC2002's ``sin(2 atan(.))``);
- ``Mz``: the aligning torque within 30 % of its peak magnitude, and
  ``Mz_slope``, the aligning stiffness (at half a degree), within 15 %. TMeasy's
  trail is a linear and a cubic law in ``s_y`` with one change of sign, PAC2002's
  a cosine of an arctangent: the largest of the differences the truth keeps
  on purpose.
"""

V_N = 0.01
"""TMeasy's fictitious speed in the slips' denominator, ``r_D |Omega| + v_N`` [m/s]:
it keeps the slips finite at standstill (Rill uses 0.01 m/s)."""

DAMPING_TIME = 0.01
"""Each deflection's damper over its spring [s]: a tyre carcass's damping ratio
of a few tenths at its 10-20 Hz modes; also the fastest rate a deflection
relaxes at once sliding, 100 /s, which explicit RK4 holds at the truth's 10 ms
(``h lambda = -1``). At standstill it damps a wheel's spin on its tread at
``a = DAMPING_TIME w0^2`` (``w0``, 140 rad/s, the spin on the tread's spring),
below ``2 w0``: the mode stays a damped oscillation at ``|lambda| = w0``, inside
RK4's region at 10 ms (``docs/design/truth.md``)."""

BORE_TWIST = math.radians(4.0)
"""Twist at which a standing tyre's bore torque reaches its friction limit at
the nominal load: truck tyres steered at standstill slide after 3 to 5 deg."""

LOAD_LIMIT = 3.0
"""Loads beyond this times the nominal load are evaluated as this (the
quadratic load law is not extrapolated further)."""


@dataclasses.dataclass(frozen=True)
class TMeasy:
    """One TMeasy tyre (SI units; slips [-], forces [N], slopes [N per unit slip]).

    Suffix ``_1`` is the value at the nominal load ``fzn``, ``_2`` at twice
    it. ``nto0`` is the trail over the patch length at zero slip, ``synto0``
    the lateral slip where the trail changes sign, ``syntoe`` where it vanishes.
    ``cx, cy`` [N/m], ``cpsi`` [N m/rad] are the tyre's longitudinal, lateral
    and torsional stiffnesses and ``dx, dy, dpsi`` their dampers; ``fr`` the
    rolling-resistance coefficient; ``vn`` [m/s] the fictitious speed.
    """

    r0: float
    cz: float
    dz: float
    fzn: float
    width: float
    fzmax: float
    dfx0_1: float
    dfx0_2: float
    fxm_1: float
    fxm_2: float
    sxm_1: float
    sxm_2: float
    fxs_1: float
    fxs_2: float
    sxs_1: float
    sxs_2: float
    dfy0_1: float
    dfy0_2: float
    fym_1: float
    fym_2: float
    sym_1: float
    sym_2: float
    fys_1: float
    fys_2: float
    sys_1: float
    sys_2: float
    nto0_1: float
    nto0_2: float
    synto0_1: float
    synto0_2: float
    syntoe_1: float
    syntoe_2: float
    cx: float
    dx: float
    cy: float
    dy: float
    cpsi: float
    dpsi: float
    fr: float
    vn: float

    def vector(self) -> np.ndarray:
        """The coefficients in the C code's order."""
        names = truthc.tyre_names()
        fields = {f.name for f in dataclasses.fields(self)}
        if set(names) != fields:
            raise RuntimeError(f"the compiled truth's tyre coefficients {sorted(names)} are "
                               f"not TMeasy's fields {sorted(fields)}: reinstall artic")
        return np.array([getattr(self, n) for n in names], dtype=float)

    def steady(self, Fz, sx, sy, sB=0.0):
        """Steady ``Fx, Fy, Mz`` at TMeasy slips (see :func:`truthc.steady`)."""
        return truthc.steady(self.vector(), Fz, sx, sy, sB)

    def relaxation_length(self, Fz: float) -> float:
        """Lateral relaxation length at small slip, ``dF0_y(Fz) / c_y`` [m]."""
        r = Fz / self.fzn
        return _quadratic(r, self.dfy0_1, self.dfy0_2) / self.cy


def _quadratic(r, x1, x2):
    """TMeasy's load law through 0, ``x1`` at ``r = 1`` and ``x2`` at ``r = 2``."""
    return r * (x1 * (2.0 - r) + x2 * 0.5 * (r - 1.0))


def pac_curves(p: TyreParams, loads: np.ndarray, n: int = 41) -> dict[str, np.ndarray]:
    """The PAC2002 curves the fit follows, per load (rows) and slip (columns).

    Returns ``kappa, alpha, alpha_m`` (the sweeps of ``Fx``, ``Fy`` and ``Mz``),
    ``sx, sy, sy_m`` (as TMeasy slips) and ``Fx, Fy, Mz``. ``Fy`` and ``Mz`` are
    the odd parts of the curves (the shipped tyres are symmetric; the odd part
    is what a symmetric model fits).
    """
    loads = np.asarray(loads, dtype=float)[:, None]
    kappa = np.linspace(-KAPPA_MAX, KAPPA_MAX, 2 * n - 1)[None, :]
    alpha = np.radians(np.linspace(0.0, ALPHA_MAX_DEG, n))[None, :]
    alpha_m = np.radians(np.linspace(0.0, MZ_ALPHA_MAX_DEG, n))[None, :]
    Fx, _, _ = steady_state(p, loads + 0 * kappa, kappa, 0 * kappa)
    _, Fy_p, _ = steady_state(p, loads + 0 * alpha, 0 * alpha, alpha)
    _, Fy_m, _ = steady_state(p, loads + 0 * alpha, 0 * alpha, -alpha)
    _, _, Mz_p = steady_state(p, loads + 0 * alpha_m, 0 * alpha_m, alpha_m)
    _, _, Mz_m = steady_state(p, loads + 0 * alpha_m, 0 * alpha_m, -alpha_m)
    return {"kappa": kappa[0], "alpha": alpha[0], "alpha_m": alpha_m[0],
            "sx": (kappa / (1.0 + kappa))[0], "sy": np.tan(alpha)[0],
            "sy_m": np.tan(alpha_m)[0], "Fx": Fx, "Fy": 0.5 * (Fy_p - Fy_m),
            "Mz": 0.5 * (Mz_p - Mz_m)}


def _with(base: TMeasy, names: tuple[str, ...], x: np.ndarray) -> TMeasy:
    return dataclasses.replace(base, **dict(zip(names, map(float, x), strict=True)))


def _peak(s: np.ndarray, F: np.ndarray) -> tuple[float, float]:
    k = int(np.argmax(F))
    return float(s[k]), float(F[k])


@functools.lru_cache(maxsize=16)
def fit(tir: str | Path, scaling: tuple[tuple[str, float], ...] = ()) -> TMeasy:
    """The TMeasy tyre of a ``.tir`` file's steady-state curves (see the module docstring).

    Parameters
    ----------
    tir : str or Path
        The property file.
    scaling : tuple of (str, float)
        PAC2002 scaling factors applied first (a vehicle file's ``tyre.scaling``).
    """
    from scipy.optimize import least_squares  # here: scipy.optimize takes 0.7 s to import

    f = read_tir(tir)
    p = scaled(TyreParams.from_tir(f), scaling)
    Fzn = p.FNOMIN
    loads = Fzn * np.array(FIT_LOADS)
    c = pac_curves(p, loads)
    two = np.array([Fzn, 2.0 * Fzn])
    Kx = p.PKX1 * p.LKX * two  # PKX2 = PKX3 = 0 in the files this fits; see the test
    Ky = np.asarray(p.cornering_stiffness(two))
    cx = float(Kx[0] / p.sigma_kappa(np.array(Fzn)))
    cy = float(Ky[0] / p.sigma_alpha(np.array(Fzn)))
    # The curves at the two reference loads give the starting values.
    ref = pac_curves(p, two, n=201)
    start = {}
    for axis, s, F, K in (("x", ref["sx"][ref["kappa"] >= 0], ref["Fx"][:, ref["kappa"] >= 0],
                           Kx), ("y", ref["sy"], ref["Fy"], Ky)):
        for i in (0, 1):
            sM, FM = _peak(s, F[i])
            start.update({f"df{axis}0_{i + 1}": float(K[i]), f"f{axis}m_{i + 1}": FM,
                          f"s{axis}m_{i + 1}": sM, f"f{axis}s_{i + 1}": 0.9 * FM,
                          f"s{axis}s_{i + 1}": 3.0 * sM})
    width = f.number("WIDTH", 2.0 * 0.3 * p.UNLOADED_RADIUS)
    base = TMeasy(r0=p.UNLOADED_RADIUS, cz=p.VERTICAL_STIFFNESS, dz=p.VERTICAL_DAMPING,
                  fzn=Fzn, width=width, fzmax=LOAD_LIMIT * Fzn, **start,
                  nto0_1=0.17, nto0_2=0.17, synto0_1=0.2, synto0_2=0.2, syntoe_1=0.5,
                  syntoe_2=0.5, cx=cx, dx=DAMPING_TIME * cx, cy=cy, dy=DAMPING_TIME * cy,
                  cpsi=1.0, dpsi=DAMPING_TIME, fr=p.QSY1 * p.LMY, vn=V_N)
    Fz = loads[:, None]
    peak_x = np.max(np.abs(c["Fx"]), axis=1, keepdims=True)
    peak_y = np.max(np.abs(c["Fy"]), axis=1, keepdims=True)
    # The slopes at zero slip: TMeasy's quadratic load law through the file's
    # slip stiffnesses, least squares in relative terms over the loads.
    r = np.array(FIT_LOADS)
    basis = np.column_stack([r * (2.0 - r), 0.5 * r * (r - 1.0)])
    for axis, K in (("x", p.PKX1 * p.LKX * loads), ("y", np.asarray(p.cornering_stiffness(loads)))):
        x = np.linalg.lstsq(basis / K[:, None], np.ones_like(K), rcond=None)[0]
        base = dataclasses.replace(base, **{f"df{axis}0_1": float(x[0]),
                                            f"df{axis}0_2": float(x[1])})
    for axis, curve, slip, peak in (("x", c["Fx"], c["sx"], peak_x),
                                    ("y", c["Fy"], c["sy"], peak_y)):
        names = tuple(f"{q}_{i}" for q in (f"f{axis}m", f"s{axis}m", f"f{axis}s", f"s{axis}s")
                      for i in (1, 2))

        def residual(x, names=names, axis=axis, curve=curve, slip=slip, peak=peak, base=base):
            t = _with(base, names, x)
            sx, sy = (slip, 0.0) if axis == "x" else (0.0, slip)
            Fx, Fy, _ = t.steady(Fz, sx, sy)
            return (((Fx if axis == "x" else Fy) - curve) / peak).ravel()

        x0 = np.array([getattr(base, n) for n in names])
        res = least_squares(residual, x0, bounds=(1e-3 * x0, 10.0 * x0), x_scale=x0,
                            method="trf")
        base = _with(base, names, res.x)
    names = ("nto0_1", "nto0_2", "synto0_1", "synto0_2", "syntoe_1", "syntoe_2")
    peak_m = np.max(np.abs(c["Mz"]), axis=1, keepdims=True)

    # Small slip angles weigh more: the aligning stiffness at yard slips
    # (a few degrees) matters more than the torque past its change of sign.
    weight = 1.0 / np.hypot(1.0, c["alpha_m"] / math.radians(5.0))

    def residual_m(x):
        _, _, Mz = _with(base, names, x).steady(Fz, 0.0, c["sy_m"])
        return ((Mz - c["Mz"]) / peak_m * weight).ravel()

    x0 = np.array([getattr(base, n) for n in names])
    res = least_squares(residual_m, x0, bounds=([0.0, 0.0, 0.01, 0.01, 0.02, 0.02],
                                                [1.0, 1.0, 1.0, 1.0, 2.0, 2.0]), method="trf")
    base = _with(base, names, res.x)
    # The bore torque slides at BORE_TWIST at the nominal load: M_max = R_B F_M there.
    L = 2.0 * math.sqrt(base.r0 * Fzn / base.cz)
    rb = (0.5 * L + 0.5 * base.width) / 3.0
    cpsi = rb * base.fym_1 / BORE_TWIST
    return dataclasses.replace(base, cpsi=cpsi, dpsi=DAMPING_TIME * cpsi)


def fit_errors(t: TMeasy, p: TyreParams) -> dict[str, float]:
    """The largest misfits over :data:`FIT_LOADS`, as :data:`TOLERANCE` states them."""
    loads = p.FNOMIN * np.array(FIT_LOADS)
    c = pac_curves(p, loads)
    Fz = loads[:, None]
    Fx, _, _ = t.steady(Fz, c["sx"], 0.0)
    _, Fy, _ = t.steady(Fz, 0.0, c["sy"])
    _, _, Mz = t.steady(Fz, 0.0, c["sy_m"])
    out = {}
    for name, got, want in (("Fx", Fx, c["Fx"]), ("Fy", Fy, c["Fy"]), ("Mz", Mz, c["Mz"])):
        peak = np.max(np.abs(want), axis=1, keepdims=True)
        out[name] = float(np.max(np.abs(got - want) / peak))
    h = 1e-5  # slope by central difference, well inside the linear range
    kx = (t.steady(loads, h, 0.0)[0] - t.steady(loads, -h, 0.0)[0]) / (2 * h)
    ky = (t.steady(loads, 0.0, h)[1] - t.steady(loads, 0.0, -h)[1]) / (2 * h)
    Kx = p.PKX1 * p.LKX * loads
    Ky = np.asarray(p.cornering_stiffness(loads))
    out["slope"] = float(max(np.max(np.abs(kx / Kx - 1.0)), np.max(np.abs(ky / Ky - 1.0))))
    a = math.radians(0.5)  # the aligning stiffness, from half a degree
    km = t.steady(loads, 0.0, math.tan(a))[2]
    _, _, want = steady_state(p, loads, 0.0 * loads, a + 0.0 * loads)
    out["Mz_slope"] = float(np.max(np.abs(km / want - 1.0)))
    return out
