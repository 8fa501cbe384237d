"""PAC2002 Magic Formula tyre with transient slip, for the multibody plant.

Forces from a ``.tir`` property file: pure-slip longitudinal and lateral
forces with load dependence, combined-slip weighting, and rolling resistance.
Camber is taken as zero; the plant's wheels stay upright to within the
suspension's roll, a fraction of a degree at yard speeds.

Conventions. Inputs and outputs are in the wheel's ISO 8855 frame: x along
the wheel heading, y to the left. The slip angle ``alpha = -atan(V_y / |V_x|)``
is positive when the contact patch slides to the right. A positive slip angle
gives a positive, leftward force, as in the reduced models. The property file
uses the opposite slip-angle sign (its ``PKY1 < 0``); the evaluation mirrors the
angle once, inside :func:`forces`. A tyre mounted on the other side from
``TYRESIDE`` is mirrored, ``F_y(alpha) -> -F_y(-alpha)``, so that conicity and
ply-steer shifts cancel across an axle.

Transient slip. Each wheel carries two tread deflections, ``u`` (longitudinal)
and ``v`` (lateral) [m], which obey

    du/dt = -V_sx - |V_x| u / sigma_kappa,     kappa' = u / sigma_kappa
    dv/dt = -V_y  - |V_x| v / sigma_alpha,     alpha' = atan(v / sigma_alpha)

with ``V_sx = V_x - Omega R_e`` the slip velocity. At speed they relax to the
steady-state slips with time constants ``sigma / |V_x|``. At ``V_x = 0`` they
turn into tread springs, so forces stay finite and smooth through standstill
and change of direction, with no division by the speed anywhere. Below
``VXLOW`` a damper proportional to the slip velocity, faded out
with ``(1 + cos(pi |V_x| / VXLOW)) / 2``, damps the tread-spring oscillation.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np

from mjcf.tir import TirFile, read_tir


class TyreRangeWarning(UserWarning):
    """A wheel left the range the tyre property file is valid for."""


@dataclass(frozen=True)
class TyreParams:
    """PAC2002 coefficients read from a ``.tir`` file (zero camber subset).

    Field names are the file's keys. ``side`` is +1 for a file measured on a
    left-mounted tyre, -1 for a right-mounted one.
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
            if f.name in ("VXLOW", "PTX4", "QSY2", "QSY3", "QSY4", "PEY3", "PEX4"):
                default = {"VXLOW": 1.0}.get(f.name, 0.0)
            values[f.name] = tir.number(f.name, default)
        side = -1.0 if tir.text("TYRESIDE", "LEFT").upper().startswith("R") else 1.0
        return cls(path=tir.path, side=side, **values)

    @property
    def Fz0(self) -> float:
        """Scaled nominal load ``FNOMIN * LFZO`` [N]."""
        return self.FNOMIN * self.LFZO

    def cornering_stiffness(self, Fz: np.ndarray | float) -> np.ndarray | float:
        """Cornering stiffness ``|K_y_alpha|`` at zero camber [N/rad]."""
        Fz0 = self.Fz0
        return abs(self.PKY1 * Fz0 * np.sin(2.0 * np.arctan(Fz / (self.PKY2 * Fz0)))
                   * self.LFZO * self.LKY)

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


def forces(p: TyreParams, Fz: np.ndarray, kappa: np.ndarray, alpha: np.ndarray,
           side: np.ndarray | float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Steady-state tyre forces for given slips (PAC2002, zero camber).

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
    side : ndarray or float
        +1 where the tyre is mounted on the side its file was measured on.

    Returns
    -------
    Fx, Fy : ndarray
        Longitudinal and lateral force in the wheel's ISO frame [N].
    """
    Fz = np.maximum(np.asarray(Fz, dtype=float), 0.0)
    s = np.asarray(side, dtype=float) * p.side
    a = -s * np.asarray(alpha, dtype=float)  # the file's slip angle, mirrored per side
    k = np.asarray(kappa, dtype=float)
    Fz0 = p.Fz0
    dfz = (Fz - Fz0) / Fz0
    # Longitudinal, pure slip.
    SHx = (p.PHX1 + p.PHX2 * dfz) * p.LHX
    kx = k + SHx
    Cx = p.PCX1 * p.LCX
    Dx = (p.PDX1 + p.PDX2 * dfz) * p.LMUX * Fz
    Ex = np.minimum((p.PEX1 + p.PEX2 * dfz + p.PEX3 * dfz ** 2)
                    * (1.0 - p.PEX4 * np.sign(kx)) * p.LEX, 1.0)
    Kx = Fz * (p.PKX1 + p.PKX2 * dfz) * np.exp(p.PKX3 * dfz) * p.LKX
    Bx = Kx / np.where(Cx * Dx != 0.0, Cx * Dx, 1.0)
    SVx = Fz * (p.PVX1 + p.PVX2 * dfz) * p.LVX * p.LMUX
    Fx0 = _mf(Bx, Cx, Dx, Ex, kx) + SVx
    # Lateral, pure slip.
    SHy = (p.PHY1 + p.PHY2 * dfz) * p.LHY
    ay = a + SHy
    Cy = p.PCY1 * p.LCY
    muy = (p.PDY1 + p.PDY2 * dfz) * p.LMUY
    Dy = muy * Fz
    Ey = np.minimum((p.PEY1 + p.PEY2 * dfz) * (1.0 - p.PEY3 * np.sign(ay)) * p.LEY, 1.0)
    Ky = p.PKY1 * Fz0 * np.sin(2.0 * np.arctan(Fz / (p.PKY2 * Fz0))) * p.LFZO * p.LKY
    By = Ky / np.where(Cy * Dy != 0.0, Cy * Dy, 1.0)
    SVy = Fz * (p.PVY1 + p.PVY2 * dfz) * p.LVY * p.LMUY
    Fy0 = _mf(By, Cy, Dy, Ey, ay) + SVy
    # Combined slip.
    Bxa = p.RBX1 * np.cos(np.arctan(p.RBX2 * k)) * p.LXAL
    Gxa = _weight(Bxa, p.RCX1, p.REX1 + p.REX2 * dfz, a, p.RHX1)
    Byk = p.RBY1 * np.cos(np.arctan(p.RBY2 * (a - p.RBY3))) * p.LYKA
    Gyk = _weight(Byk, p.RCY1, p.REY1 + p.REY2 * dfz, k, p.RHY1 + p.RHY2 * dfz)
    DVyk = muy * Fz * (p.RVY1 + p.RVY2 * dfz) * np.cos(np.arctan(p.RVY4 * a))
    SVyk = DVyk * np.sin(p.RVY5 * np.arctan(p.RVY6 * k)) * p.LVYKA
    Fx = Gxa * Fx0
    Fy = s * (Gyk * Fy0 + SVyk)
    return Fx, Fy


def rolling_resistance(p: TyreParams, Fz: np.ndarray, Vx: np.ndarray,
                       v_smooth: float = 0.05) -> np.ndarray:
    """Rolling-resistance moment about the wheel's spin axis [N m].

    ``M_y = -R0 Fz (QSY1 + QSY3 |V_x| / LONGVL + QSY4 (V_x / LONGVL)^4) LMY``, with
    the sign of rolling smoothed over ``v_smooth`` [m/s] so that it fades
    to zero at standstill instead of switching.
    """
    Fz = np.maximum(Fz, 0.0)
    vr = np.abs(Vx) / p.LONGVL
    mag = p.UNLOADED_RADIUS * Fz * (p.QSY1 + p.QSY3 * vr + p.QSY4 * vr ** 4) * p.LMY
    return -mag * np.tanh(Vx / v_smooth)


def deflection_rates(p: TyreParams, Fz: np.ndarray, Vx: np.ndarray, Vsx: np.ndarray,
                     Vy: np.ndarray, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rates of the tread deflections ``(du/dt, dv/dt)`` [m/s] (see the module docstring).

    Parameters
    ----------
    Vx, Vy : ndarray
        Contact-point velocity in the wheel frame [m/s].
    Vsx : ndarray
        Longitudinal slip velocity ``V_x - Omega R_e`` [m/s].
    u, v : ndarray
        Deflections [m].
    """
    Fz = np.maximum(Fz, p.FZMIN)
    ax = np.abs(Vx)
    return (-Vsx - ax * u / p.sigma_kappa(Fz), -Vy - ax * v / p.sigma_alpha(Fz))


def transient_forces(p: TyreParams, Fz: np.ndarray, Vx: np.ndarray, Vsx: np.ndarray,
                     Vy: np.ndarray, u: np.ndarray, v: np.ndarray,
                     side: np.ndarray | float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Forces from the deflection states, with low-speed damping [N].

    Returns
    -------
    Fx, Fy : ndarray
        In the wheel's ISO frame [N].
    """
    Fzc = np.maximum(Fz, p.FZMIN)
    kappa = u / p.sigma_kappa(Fzc)
    alpha = np.arctan(v / p.sigma_alpha(Fzc))
    Fx, Fy = forces(p, Fz, kappa, alpha, side)
    # Damping of the tread springs below VXLOW: the tyre's own stiffness over
    # its relaxation length, a quarter of it as a damping rate [1/s].
    fade = np.where(np.abs(Vx) < p.VXLOW,
                    0.5 * (1.0 + np.cos(math.pi * np.abs(Vx) / p.VXLOW)), 0.0)
    Kx = np.maximum(Fz, 0.0) * p.PKX1 * p.LKX
    Ky = p.cornering_stiffness(np.maximum(Fz, 0.0))
    Fx = Fx - fade * p.PTX4 * Kx / p.sigma_kappa(Fzc) * Vsx * 0.25
    Fy = Fy - fade * p.PTX4 * Ky / p.sigma_alpha(Fzc) * Vy * 0.25
    return Fx, Fy


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
