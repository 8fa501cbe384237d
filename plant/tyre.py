"""PAC2002 Magic Formula tyre with transient slip, for the multibody plant.

Forces and moments from a ``.tir`` property file (MF-Tyre 5.2 level, zero
camber): pure-slip longitudinal and lateral forces with load dependence,
combined-slip weighting, the aligning moment (pneumatic trail and residual
torque, combined slip), rolling resistance, and a bore (turn-slip) torque.
Camber is taken as zero; the plant's wheels stay upright to within the
suspension's roll, a fraction of a degree at yard speeds.

Conventions. Inputs and outputs are in the wheel's ISO 8855 frame: x along
the wheel heading, y to the left, z up. The slip angle
``alpha = -atan(V_y / |V_x|)`` is positive when the contact patch slides to the
right. A positive slip angle gives a positive, leftward force, as in the
reduced models. The property file uses the opposite slip-angle sign (its
``PKY1 < 0``); the evaluation turns the angle once, inside
:func:`steady_state`, and evaluates the lateral Magic Formula at its tangent,
``alpha* = tan(alpha_file)`` (Pacejka 2006, eq. 4.E3), which is the
tread-deflection ratio ``v / sigma_alpha`` itself. ``Mz`` is about the wheel's
z-axis: a positive slip angle gives a negative, self-aligning moment here,
which is the file's positive ``Mz`` at its positive slip angle.

Mounting side. A tyre mounted on the other side of the vehicle, outer
sidewall outward as always, is the same tyre turned half a revolution about
the vertical, so it rolls the other way round relative to its construction.
Its lateral offset at zero slip has two parts:

- conicity, from the tyre's geometry, does not depend on the rolling
  direction: the half turn mirrors it, and it pushes the opposite way in
  vehicle axes (outward on both sides, say);
- ply steer, from the belt's ply angles, reverses with the rolling
  direction: that reversal and the half turn cancel, and it pushes the same
  way in vehicle axes on both sides. So does its residual aligning torque.

MF-Tyre's TYRESIDE mirrors the whole lateral characteristic for a tyre used
on the other side, ``Fy_m(alpha) = -Fy(-alpha)`` and ``Mz_m(alpha) = -Mz(-alpha)``,
which treats all of the offset as conicity; on a vehicle the offsets of the left
and right tyres then cancel on every axle, and no combination drifts. A
PAC2002 file has one offset per quantity (``PHY1``, ``PHY2``, ``PVY1``,
``PVY2``, ``QHZ1``, ``QHZ2``, ``QDZ6``, ``QDZ7``, and the asymmetry terms
``PEY3``, ``RBY3``, ``RVY1``, ``RVY2``, ``RHX1``, ``SSZ1``) and cannot tell
the two parts apart. artic treats all of it as ply steer, which is the
larger and systematic part on radial truck tyres (conicity varies from tyre
to tyre around zero), so every wheel end uses the file as measured and
``TYRESIDE`` is read but not applied: the tyre behaves alike on both sides
and a combination with an offset crabs at its tyres' zero-force slip angle
and drifts, as real ones do. The only terms that would flip with the side,
the camber terms (the inclination angle's sign turns with the side), are
not used: camber is taken as zero.

Transient slip. Each wheel carries three tread deflections, ``u``
(longitudinal) and ``v`` (lateral) [m] and the twist ``phi`` [rad], which obey

    du/dt   = -V_sx - |V_x| u / sigma_kappa,     kappa' = u / sigma_kappa
    dv/dt   = -V_y  - |V_x| v / sigma_alpha,     tan(alpha') = v / sigma_alpha
    dphi/dt = -omega_z - |omega_z| phi / phi_lim - |V_x| phi / a

with ``V_sx = V_x - Omega R_e`` the slip velocity, ``omega_z`` the wheel's yaw
rate about the ground normal and ``a`` the contact patch's half-length. At
speed they relax to the steady-state slips with time constants ``sigma / |V_x|``.
At ``V_x = 0`` they turn into tread springs, so forces and moments stay finite
and smooth through standstill and change of direction, with no division by
the speed anywhere. Below ``VXLOW`` a damper, faded out with
``(1 + cos(pi |V_x| / VXLOW)) / 2``, damps the tread-spring oscillation: on
the slip velocity for ``u`` and ``v``, on the twist's elastic rate (its rate
times the torque's slope, so nothing once the patch slides) for ``phi``.
With the wheel's spin inertia, the damped longitudinal tread is the plant's
fastest mode (a real root near -430 1/s at standstill); the plant integrates
it fitted to its step (:mod:`artic.plant.spinmode`). The sign of travel in the
trail and the rolling resistance is smoothed over :data:`V_SIGN`.

Bore torque (turn slip), a documented contact-patch model, as a PAC2002 file
has no turn-slip coefficients (an MF 6.1 file's ``PDXP1`` to ``QDRP1`` are not
read; the model's own constants, :data:`TWIST_STIFFNESS`, :data:`TWIST_LIMIT`
and :data:`PATCH_MIN`, stand for them): the twist ``phi`` gives a torque
``M_bore = M_max tanh(phi / phi_s)`` about the ground normal, with

- ``M_max = (2/3) mu_y Fz a``, the friction torque of a circular patch of
  radius ``a`` under uniform pressure, so the torque is bounded by friction;
- ``a = sqrt(R0 Fz / k_t)``, ``1/sqrt(2)`` of the half-chord that the ground
  cuts from the undeformed tyre deflected by ``Fz / k_t`` (the tread flattens
  over less than the chord): 0.13 m for a truck tyre at 30 kN, whose
  footprint is about 0.25 m long and as wide, so a circle of radius ``a``
  stands in for it (a square of side ``2 a`` would give 15 % more torque);
  at least :data:`PATCH_MIN`;
- ``phi_s = M_max / K_phi = (2/3) mu_y a / TWIST_STIFFNESS`` (about 0.05 rad),
  with the torsional stiffness of a standing tyre ``K_phi = TWIST_STIFFNESS Fz``.

The twist is a friction element, not a spring: the term in ``|omega_z|``
(Dahl's solid-friction model) stops it growing at ``phi_lim = TWIST_LIMIT
phi_s``, where the patch slides as a whole. A wheel turned at standstill
twists its tread up to the friction torque within a few degrees and then
slides; turned back, the twist unwinds and the torque reverses after
``ln(2) phi_lim`` (5 deg), as a tread re-anchored where it slid, instead of
pulling the wheel back to where it stood first. A steered, parked tyre holds
its twist and so its torque, instead of chattering. Rolling carries the twist
away within the patch: in a turn of radius ``R`` it settles at
``-a / (R + a / phi_lim)``, ``-a / R`` in wide turns and ``-phi_lim`` when
the wheel pivots on its patch. With the damper the torque stays within
``M_max`` for yaw rates up to ``0.85 phi_s / (0.25 PTX4)`` [rad/s] (1 to 2
rad/s for artic's tyre from 10 to 50 kN, twice a truck's fastest steering at
standstill and more), and tends to it once the patch slides.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np

from artic.mjcf.tir import TirFile, read_tir

TWIST_STIFFNESS = 1.33
"""Torsional stiffness of a standing tyre per unit load [N m/rad per N]: about
40 kN m/rad at 30 kN, as measured on truck tyres twisted at standstill."""

TWIST_LIMIT = 2.5
"""Twist at which the patch slides as a whole, in units of ``phi_s`` [-]: the
torque there is ``tanh(2.5)``, 98.7 % of the friction torque."""

TWIST_MIN = 1e-3
"""Smallest ``phi_s`` used [rad] (no friction at all: no division by zero)."""

PATCH_MIN = 0.02
"""Smallest contact half-length used [m] (an unloaded wheel: no division by zero)."""

EPS = 1e-6
"""The Magic Formula's small number against division by zero (4.E39)."""

V_SIGN = 0.05
"""Speed over which the sign of travel is smoothed [m/s] (rolling resistance, trail)."""

ZERO_DEFAULT = ("PTX4", "QSY2", "QSY3", "QSY4", "PEY3", "PEX4", "QBZ1", "QBZ2", "QBZ3",
                "QBZ9", "QBZ10", "QCZ1", "QDZ1", "QDZ2", "QDZ6", "QDZ7", "QEZ1", "QEZ2",
                "QEZ3", "QEZ4", "QHZ1", "QHZ2", "SSZ1", "SSZ2")
"""Coefficients that default to zero when a file leaves them out (no aligning
moment without the trail's coefficients)."""


class TyreRangeWarning(UserWarning):
    """A wheel left the range the tyre property file is valid for."""


@dataclass(frozen=True)
class TyreParams:
    """PAC2002 coefficients read from a ``.tir`` file (zero camber subset).

    Field names are the file's keys. ``side`` is +1 for a file measured on a
    left-mounted tyre, -1 for a right-mounted one (``TYRESIDE``); it is kept
    for reference and not applied (see "Mounting side" in the module docstring).
    """

    path: str
    side: float
    UNLOADED_RADIUS: float
    VERTICAL_STIFFNESS: float
    VERTICAL_DAMPING: float
    FNOMIN: float
    LONGVL: float
    VXLOW: float
    FZMIN: float
    FZMAX: float
    KPUMIN: float
    KPUMAX: float
    ALPMIN: float
    ALPMAX: float
    LFZO: float
    LCX: float
    LEX: float
    LKX: float
    LHX: float
    LVX: float
    LMUX: float
    LCY: float
    LEY: float
    LKY: float
    LHY: float
    LVY: float
    LMUY: float
    LXAL: float
    LYKA: float
    LVYKA: float
    LMY: float
    LSGKP: float
    LSGAL: float
    PCX1: float
    PDX1: float
    PDX2: float
    PEX1: float
    PEX2: float
    PEX3: float
    PEX4: float
    PKX1: float
    PKX2: float
    PKX3: float
    PHX1: float
    PHX2: float
    PVX1: float
    PVX2: float
    RBX1: float
    RBX2: float
    RCX1: float
    REX1: float
    REX2: float
    RHX1: float
    PTX1: float
    PTX2: float
    PTX3: float
    PTX4: float
    PCY1: float
    PDY1: float
    PDY2: float
    PEY1: float
    PEY2: float
    PEY3: float
    PKY1: float
    PKY2: float
    PHY1: float
    PHY2: float
    PVY1: float
    PVY2: float
    RBY1: float
    RBY2: float
    RBY3: float
    RCY1: float
    REY1: float
    REY2: float
    RHY1: float
    RHY2: float
    RVY1: float
    RVY2: float
    RVY4: float
    RVY5: float
    RVY6: float
    PTY1: float
    PTY2: float
    QSY1: float
    QSY2: float
    QSY3: float
    QSY4: float
    LTR: float
    LRES: float
    LS: float
    QBZ1: float
    QBZ2: float
    QBZ3: float
    QBZ9: float
    QBZ10: float
    QCZ1: float
    QDZ1: float
    QDZ2: float
    QDZ6: float
    QDZ7: float
    QEZ1: float
    QEZ2: float
    QEZ3: float
    QEZ4: float
    QHZ1: float
    QHZ2: float
    SSZ1: float
    SSZ2: float

    @classmethod
    def from_tir(cls, tir: TirFile | str | Path) -> TyreParams:
        """Read the coefficients; scaling factors default to 1, shifts to 0."""
        if not isinstance(tir, TirFile):
            tir = read_tir(tir)
        values: dict[str, float] = {}
        for f in fields(cls):
            if f.name in ("path", "side"):
                continue
            default = 1.0 if f.name.startswith("L") and f.name != "LONGVL" else None
            if f.name == "VXLOW":
                default = 1.0
            elif f.name in ZERO_DEFAULT:
                default = 0.0
            values[f.name] = tir.number(f.name, default)
        side = -1.0 if tir.text("TYRESIDE", "LEFT").upper().startswith("R") else 1.0
        return cls(path=tir.path, side=side, **values)

    @property
    def Fz0(self) -> float:
        """Scaled nominal load ``FNOMIN * LFZO`` [N]."""
        return self.FNOMIN * self.LFZO

    def cornering_stiffness(self, Fz: np.ndarray | float) -> np.ndarray | float:
        """Cornering stiffness ``|K_y_alpha|`` at zero camber [N/rad].

        ``PKY1 Fz0' sin(2 atan(Fz / (PKY2 Fz0'))) LKY`` with ``Fz0' = LFZO FNOMIN``
        (4.E25): LFZO enters through ``Fz0'`` only.
        """
        Fz0 = self.Fz0
        return abs(self.PKY1 * Fz0 * np.sin(2.0 * np.arctan(Fz / (self.PKY2 * Fz0))) * self.LKY)

    def patch_half_length(self, Fz: np.ndarray | float) -> np.ndarray | float:
        """Contact half-length ``a = sqrt(R0 Fz / k_t)``, at least PATCH_MIN [m]."""
        return np.maximum(np.sqrt(self.UNLOADED_RADIUS * np.maximum(Fz, 0.0)
                                  / self.VERTICAL_STIFFNESS), PATCH_MIN)

    def twist_scale(self, Fz: np.ndarray | float) -> np.ndarray | float:
        """Twist ``phi_s = (2/3) mu_y a / TWIST_STIFFNESS`` of the bore torque [rad].

        The load is taken at least ``FZMIN``; ``phi_s`` is at least :data:`TWIST_MIN`.
        """
        Fz = np.maximum(Fz, self.FZMIN)
        mu = (self.PDY1 + self.PDY2 * (Fz - self.Fz0) / self.Fz0) * self.LMUY
        return np.maximum((2.0 / 3.0) * mu * self.patch_half_length(Fz) / TWIST_STIFFNESS,
                          TWIST_MIN)

    def sigma_alpha(self, Fz: np.ndarray) -> np.ndarray:
        """Lateral relaxation length [m]."""
        return (self.PTY1 * np.sin(2.0 * np.arctan(Fz / (self.PTY2 * self.Fz0)))
                * self.UNLOADED_RADIUS * self.LFZO * self.LSGAL)

    def sigma_kappa(self, Fz: np.ndarray) -> np.ndarray:
        """Longitudinal relaxation length [m]."""
        dfz = (Fz - self.Fz0) / self.Fz0
        return (Fz * (self.PTX1 + self.PTX2 * dfz) * np.exp(-self.PTX3 * dfz)
                * self.UNLOADED_RADIUS / self.Fz0 * self.LSGKP)


def _mf(B, C, D, E, x):
    """The Magic Formula ``D sin(C atan(B x - E (B x - atan(B x))))``."""
    bx = B * x
    return D * np.sin(C * np.arctan(bx - E * (bx - np.arctan(bx))))


def _weight(B, C, E, x, shift):
    """Combined-slip weighting ``G = cos(C atan(B x_s - E ...)) / G0``."""
    def g(z):
        bz = B * z
        return np.cos(C * np.arctan(bz - E * (bz - np.arctan(bz))))
    return g(x + shift) / g(shift)


def steady_state(p: TyreParams, Fz: np.ndarray, kappa: np.ndarray, alpha: np.ndarray,
                 v_sign: np.ndarray | float = 1.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Steady-state forces and aligning moment for given slips (PAC2002, zero camber).

    Parameters
    ----------
    p : TyreParams
        Coefficients.
    Fz : ndarray
        Vertical load [N]; forces vanish for ``Fz <= 0``.
    kappa : ndarray
        Longitudinal slip ``-V_sx / |V_x|`` [-], positive when driving.
    alpha : ndarray
        ISO slip angle [rad], positive when sliding to the right.
    v_sign : ndarray or float
        Sign of travel, ``sign(V_x)`` (smoothed by the caller through standstill):
        the pneumatic trail and the residual torque turn with it.

    Returns
    -------
    Fx, Fy, Mz : ndarray
        Longitudinal and lateral force [N] and aligning moment [N m], wheel's ISO frame.
    """
    Fz = np.maximum(np.asarray(Fz, dtype=float), 0.0)
    a = -np.asarray(alpha, dtype=float)  # the file's slip angle
    ta = np.tan(a)  # alpha* (4.E3)
    ca = np.cos(a)  # cos'(alpha) = V_cx / V_c
    k = np.asarray(kappa, dtype=float)
    Fz0 = p.Fz0
    dfz = (Fz - Fz0) / Fz0
    # Longitudinal, pure slip (4.E9-4.E18).
    SHx = (p.PHX1 + p.PHX2 * dfz) * p.LHX
    kx = k + SHx
    Cx = p.PCX1 * p.LCX
    Dx = (p.PDX1 + p.PDX2 * dfz) * p.LMUX * Fz
    Ex = np.minimum((p.PEX1 + p.PEX2 * dfz + p.PEX3 * dfz ** 2)
                    * (1.0 - p.PEX4 * np.where(kx >= 0.0, 1.0, -1.0)) * p.LEX, 1.0)
    Kx = Fz * (p.PKX1 + p.PKX2 * dfz) * np.exp(p.PKX3 * dfz) * p.LKX
    Bx = Kx / np.where(Cx * Dx != 0.0, Cx * Dx, 1.0)
    SVx = Fz * (p.PVX1 + p.PVX2 * dfz) * p.LVX * p.LMUX
    Fx0 = _mf(Bx, Cx, Dx, Ex, kx) + SVx
    # Lateral, pure slip (4.E19-4.E30).
    SHy = (p.PHY1 + p.PHY2 * dfz) * p.LHY
    ay = ta + SHy
    Cy = p.PCY1 * p.LCY
    muy = (p.PDY1 + p.PDY2 * dfz) * p.LMUY
    Dy = muy * Fz
    Ey = np.minimum((p.PEY1 + p.PEY2 * dfz) * (1.0 - p.PEY3 * np.where(ay >= 0.0, 1.0, -1.0))
                    * p.LEY, 1.0)
    Ky = p.PKY1 * Fz0 * np.sin(2.0 * np.arctan(Fz / (p.PKY2 * Fz0))) * p.LKY
    By = Ky / np.where(Cy * Dy != 0.0, Cy * Dy, 1.0)
    SVy = Fz * (p.PVY1 + p.PVY2 * dfz) * p.LVY * p.LMUY
    Fy0 = _mf(By, Cy, Dy, Ey, ay) + SVy
    # Combined slip (4.E50-4.E67).
    Bxa = p.RBX1 * np.cos(np.arctan(p.RBX2 * k)) * p.LXAL
    Gxa = _weight(Bxa, p.RCX1, p.REX1 + p.REX2 * dfz, ta, p.RHX1)
    Byk = p.RBY1 * np.cos(np.arctan(p.RBY2 * (ta - p.RBY3))) * p.LYKA
    Gyk = _weight(Byk, p.RCY1, p.REY1 + p.REY2 * dfz, k, p.RHY1 + p.RHY2 * dfz)
    DVyk = muy * Fz * (p.RVY1 + p.RVY2 * dfz) * np.cos(np.arctan(p.RVY4 * ta))
    SVyk = DVyk * np.sin(p.RVY5 * np.arctan(p.RVY6 * k)) * p.LVYKA
    Fx = Gxa * Fx0
    Fy = Gyk * Fy0 + SVyk
    # Aligning moment (4.E31-4.E49, combined 4.E71-4.E78), zero camber.
    Kyp = Ky + EPS * np.where(Ky < 0.0, -1.0, 1.0)  # 4.E39
    SHt = p.QHZ1 + p.QHZ2 * dfz
    SHf = SHy + SVy / Kyp
    a_t, a_r = ta + SHt, ta + SHf
    kk = (Kx / Kyp) ** 2 * k ** 2
    at_eq = np.sqrt(a_t ** 2 + kk) * np.where(a_t >= 0.0, 1.0, -1.0)  # 4.E77, sgn(0) = 1
    ar_eq = np.sqrt(a_r ** 2 + kk) * np.where(a_r >= 0.0, 1.0, -1.0)  # 4.E78
    Bt = (p.QBZ1 + p.QBZ2 * dfz + p.QBZ3 * dfz ** 2) * p.LKY / p.LMUY
    Ct = p.QCZ1
    Dt = Fz * (p.UNLOADED_RADIUS / Fz0) * (p.QDZ1 + p.QDZ2 * dfz) * p.LTR * v_sign
    Et = np.minimum((p.QEZ1 + p.QEZ2 * dfz + p.QEZ3 * dfz ** 2)
                    * (1.0 + p.QEZ4 * (2.0 / math.pi) * np.arctan(Bt * Ct * a_t)), 1.0)
    bt = Bt * at_eq
    trail = Dt * np.cos(Ct * np.arctan(bt - Et * (bt - np.arctan(bt)))) * ca  # 4.E73
    Br = p.QBZ9 * p.LKY / p.LMUY + p.QBZ10 * By * Cy
    Dr = Fz * p.UNLOADED_RADIUS * (p.QDZ6 + p.QDZ7 * dfz) * p.LRES * p.LMUY * v_sign * ca
    Mzr = Dr * np.cos(np.arctan(Br * ar_eq))  # 4.E75
    Fy_prime = Gyk * Fy0  # Fy at zero camber, without the kappa-induced SVyk
    s_arm = p.UNLOADED_RADIUS * (p.SSZ1 + p.SSZ2 * (Fy / Fz0)) * p.LS
    Mz = -trail * Fy_prime + Mzr + s_arm * Fx
    return Fx, Fy, Mz


def forces(p: TyreParams, Fz: np.ndarray, kappa: np.ndarray,
           alpha: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Steady-state ``(Fx, Fy)`` [N]; see :func:`steady_state`."""
    Fx, Fy, _ = steady_state(p, Fz, kappa, alpha)
    return Fx, Fy


def rolling_resistance(p: TyreParams, Fz: np.ndarray, Vx: np.ndarray,
                       Fx: np.ndarray | float = 0.0) -> np.ndarray:
    """Rolling-resistance moment about the wheel's spin axis [N m].

    ``M_y = -R0 Fz (QSY1 + QSY2 Fx / Fz0 + QSY3 |V_x| / LONGVL + QSY4 (V_x / LONGVL)^4) LMY``
    (PAC2002's 4.E69 with the travel sign), the sign of rolling smoothed over
    :data:`V_SIGN` so that it fades to zero at standstill instead of switching.
    """
    Fz = np.maximum(Fz, 0.0)
    vr = np.abs(Vx) / p.LONGVL
    mag = p.UNLOADED_RADIUS * Fz * (p.QSY1 + p.QSY2 * np.asarray(Fx) / p.Fz0 + p.QSY3 * vr
                                    + p.QSY4 * vr ** 4) * p.LMY
    return -mag * np.tanh(Vx / V_SIGN)


def deflection_rates(p: TyreParams, Fz: np.ndarray, Vx: np.ndarray, Vsx: np.ndarray,
                     Vy: np.ndarray, omega_z: np.ndarray, u: np.ndarray, v: np.ndarray,
                     phi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rates of the tread deflections ``(du/dt, dv/dt, dphi/dt)`` (see the module docstring).

    Parameters
    ----------
    Vx, Vy : ndarray
        Contact-point velocity in the wheel frame [m/s].
    Vsx : ndarray
        Longitudinal slip velocity ``V_x - Omega R_e`` [m/s].
    omega_z : ndarray
        The wheel's yaw rate about the ground normal [rad/s].
    u, v : ndarray
        Deflections [m].
    phi : ndarray
        Tread twist [rad].
    """
    Fz = np.maximum(Fz, p.FZMIN)
    ax = np.abs(Vx)
    return (-Vsx - ax * u / p.sigma_kappa(Fz), -Vy - ax * v / p.sigma_alpha(Fz),
            twist_rate(p, Fz, Vx, omega_z, phi))


def steady_deflections(p: TyreParams, Fz: np.ndarray, Vx: np.ndarray, Vsx: np.ndarray,
                       Vy: np.ndarray,
                       omega_z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The tread deflections ``(u, v, phi)`` at which :func:`deflection_rates` are zero.

    Each rate is linear in its deflection (the twist's piecewise so, in
    ``|omega_z|`` and ``|V_x|``): ``u = -V_sx sigma_kappa / |V_x|``,
    ``v = -V_y sigma_alpha / |V_x|`` and ``phi = -omega_z / (|omega_z| / phi_lim
    + |V_x| / a)``, ``a`` the patch's half length: the tyre that has rolled
    long enough at this motion. A wheel standing still (``V_x = 0``) has no
    steady deflection but relaxes none either: 0 there, as for ``phi`` when
    it neither rolls nor turns. Arguments as :func:`deflection_rates` [N, m/s, rad/s].
    """
    Fz = np.maximum(Fz, p.FZMIN)
    ax = np.abs(Vx)
    rolls = ax > 0.0
    safe = np.where(rolls, ax, 1.0)
    u = np.where(rolls, -Vsx * p.sigma_kappa(Fz) / safe, 0.0)
    v = np.where(rolls, -Vy * p.sigma_alpha(Fz) / safe, 0.0)
    rate = np.abs(omega_z) / (TWIST_LIMIT * p.twist_scale(Fz)) + ax / p.patch_half_length(Fz)
    phi = np.where(rate > 0.0, -omega_z / np.where(rate > 0.0, rate, 1.0), 0.0)
    return u, v, phi


def twist_rate(p: TyreParams, Fz: np.ndarray, Vx: np.ndarray, omega_z: np.ndarray,
               phi: np.ndarray) -> np.ndarray:
    """``dphi/dt`` [rad/s]: yaw, sliding beyond ``phi_lim`` and rolling relaxation."""
    Fz = np.maximum(Fz, p.FZMIN)
    phi_lim = TWIST_LIMIT * p.twist_scale(Fz)
    return -omega_z - np.abs(omega_z) * phi / phi_lim - np.abs(Vx) * phi / p.patch_half_length(Fz)


def longitudinal_tread(p: TyreParams, Fz: np.ndarray,
                       Vx: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The longitudinal tread's linear terms: what :mod:`artic.plant.spinmode` needs.

    Returns
    -------
    k : ndarray
        Tread stiffness ``K_x / sigma_kappa`` [N/m], with the damper's ``K_x =
        Fz PKX1 LKX``: the slope of ``F_x`` in ``u`` at zero slip.
    c : ndarray
        Low-speed damper on the slip velocity [N s/m] (:func:`transient_forces`):
        ``F_x`` gains ``-c V_sx``.
    b : ndarray
        Rolling relaxation rate ``|V_x| / sigma_kappa`` [1/s] (:func:`deflection_rates`).
    """
    sk = p.sigma_kappa(np.maximum(Fz, p.FZMIN))
    Kx = np.maximum(Fz, 0.0) * p.PKX1 * p.LKX
    return Kx / sk, low_speed_fade(p, Vx) * p.PTX4 * Kx / sk * 0.25, np.abs(Vx) / sk


def low_speed_fade(p: TyreParams, Vx: np.ndarray) -> np.ndarray:
    """The low-speed dampers' weight ``(1 + cos(pi |V_x| / VXLOW)) / 2`` below ``VXLOW``, else 0."""
    return np.where(np.abs(Vx) < p.VXLOW,
                    0.5 * (1.0 + np.cos(math.pi * np.abs(Vx) / p.VXLOW)), 0.0)


def bore_torque(p: TyreParams, Fz: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """Torque of the twisted tread about the ground normal [N m] (see the module docstring)."""
    Fz = np.maximum(Fz, 0.0)
    dfz = (Fz - p.Fz0) / p.Fz0
    mu = np.maximum((p.PDY1 + p.PDY2 * dfz) * p.LMUY, 0.0)
    m_max = (2.0 / 3.0) * mu * Fz * p.patch_half_length(Fz)
    return m_max * np.tanh(phi / p.twist_scale(Fz))


def transient_forces(p: TyreParams, Fz: np.ndarray, Vx: np.ndarray, Vsx: np.ndarray,
                     Vy: np.ndarray, omega_z: np.ndarray, u: np.ndarray, v: np.ndarray,
                     phi: np.ndarray,
                     moments: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Forces and moment from the deflection states, with low-speed damping.

    Parameters
    ----------
    moments : bool
        With the aligning moment and the bore torque; ``Mz`` is zero without.

    Returns
    -------
    Fx, Fy : ndarray
        In the wheel's ISO frame [N].
    Mz : ndarray
        Aligning moment plus bore torque about the ground normal [N m].
    """
    Fzc = np.maximum(Fz, p.FZMIN)
    sk, sa = p.sigma_kappa(Fzc), p.sigma_alpha(Fzc)
    kappa = u / sk
    alpha = np.arctan(v / sa)
    Fx, Fy, Mz = steady_state(p, Fz, kappa, alpha, np.tanh(Vx / V_SIGN))
    # Damping of the tread springs below VXLOW: the tyre's own stiffness over
    # its relaxation length, a quarter of it as a damping rate [1/s].
    fade = low_speed_fade(p, Vx)
    Fzp = np.maximum(Fz, 0.0)
    Kx = Fzp * p.PKX1 * p.LKX
    Ky = p.cornering_stiffness(Fzp)
    Fx = Fx - fade * p.PTX4 * Kx / sk * Vsx * 0.25
    Fy = Fy - fade * p.PTX4 * Ky / sa * Vy * 0.25
    if not moments:
        return Fx, Fy, np.zeros_like(Fx)
    # The twist's damper acts on its elastic part: the rate times the slope
    # of tanh, so it adds nothing once the patch slides (no torque past friction).
    th = np.tanh(phi / p.twist_scale(Fz))
    elastic = (1.0 - th * th) * twist_rate(p, Fz, Vx, omega_z, phi)
    Mz = Mz + bore_torque(p, Fz, phi) + fade * p.PTX4 * TWIST_STIFFNESS * Fzp * elastic * 0.25
    return Fx, Fy, Mz


def check_ranges(p: TyreParams, Fz: np.ndarray, kappa: np.ndarray, alpha: np.ndarray,
                 names: list[str] | None = None, where: str = "") -> list[str]:
    """Warn when wheels leave the file's valid ranges.

    Checks ``FZMIN <= Fz <= FZMAX``, ``KPUMIN <= kappa <= KPUMAX`` and
    ``ALPMIN <= alpha <= ALPMAX``. One :class:`TyreRangeWarning` lists every
    wheel out of range and by how much.

    Returns
    -------
    list of str
        The messages (empty when all is in range).
    """
    names = names or [f"wheel {i}" for i in range(np.size(Fz))]
    msgs = []
    for label, x, lo, hi in (("Fz", Fz, p.FZMIN, p.FZMAX), ("kappa", kappa, p.KPUMIN,
                                                             p.KPUMAX),
                             ("alpha", alpha, p.ALPMIN, p.ALPMAX)):
        x = np.atleast_1d(x)
        for i in np.flatnonzero((x < lo) | (x > hi)):
            msgs.append(f"{names[i]}: {label} = {x[i]:.4g} outside [{lo:g}, {hi:g}]")
    if msgs:
        warnings.warn(f"{p.path}{' at ' + where if where else ''}: tyre outside the file's "
                      f"valid range: " + "; ".join(msgs), TyreRangeWarning, stacklevel=2)
    return msgs
