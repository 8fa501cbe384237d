"""Independent reference implementation (test oracle) of the steady-state
Pacejka PAC2002 / MF-Tyre 5.2 Magic Formula tyre model.

Written from Pacejka, *Tyre and Vehicle Dynamics*, 2nd ed. (2006), section
4.3.2 + appendix equation list (4.E1 ... 4.E78) and section 4.3.3 (turn slip,
ζ-factors), cross-checked against the public MFeval toolbox (M. Furlan,
``+mfeval/Solver.m``, FITTYP 6 = MF5.2 branch).  Plain numpy, float64, fully
vectorised (all array arguments broadcast).  No project code was consulted.

Public API
----------
``read_tir(path) -> dict[str, float | str]``
``steady_state(p, fz, kappa, alpha, gamma=0, vx=10, phi_t=0, side=+1, *,
turn_slip=False, camber_spin=False, variant="book") -> (fx, fy, mz)``
``evaluate(...)`` same arguments, returns a dict with intermediates
(``fx0, fy0, mz0, kxk, kya, kyg0, t, mzr, s, gxa, gyk, svyk, mux, muy,
zeta0..zeta8, phi`` ...).
``cornering_stiffness(p, fz, gamma=0)`` and ``slip_stiffness(p, fz)``:
closed forms of 4.E25 and 4.E15.

Axis system and signs (ISO-W, ISO 8855 / TNO MF-Tyre convention)
-----------------------------------------------------------------
* Wheel axes: x forward (wheel heading projected on the road), y to the left,
  z up.  Fx, Fy, Mz are the forces / moment of the road on the tyre at the
  contact point, in these axes.
* kappa = -Vsx/|Vcx| (positive = driving, wheel faster than the road).
* alpha: slip angle, tan(alpha) = Vcy/Vcx (Vcy = lateral velocity of the
  contact centre, +y).  Steady state: ``Vsy = Vcy = vx*tan(alpha)``,
  ``Vc = sqrt(vx**2 + Vsy**2)``, ``cos(alpha') = Vcx/(Vc + eps)`` (4.E6).
  With an ISO .tir file PKY1 < 0, hence KYalpha < 0 and positive alpha gives
  NEGATIVE Fy:  Fy ~= KYalpha*alpha = -|KYalpha|*alpha.  The restoring
  (self-aligning) moment is then POSITIVE for positive alpha: Mz ~= -t*Fy > 0
  (turns the wheel heading towards the velocity vector, about +z).
* gamma: inclination (camber) angle, positive rotation about +x (top of the
  wheel towards -y).  Camber thrust for this file: dFy/dgamma < 0.
* "book" variant: alpha* = tan(alpha)*sgn(Vcx) (4.E3), gamma* = sin(gamma)
  (4.E4), as requested.  ("mfeval52" variant: alpha* = alpha, gamma* = gamma,
  which is MFeval's default useMode 1x1 = TNO MF-Tyre behaviour.)
* Not modelled (steady-state Fx/Fy/Mz only): Mx, My (QSY* rolling resistance,
  QSY2 etc. ignored), relaxation (LSGKP, LSGAL), gyroscopic torque (LGYR),
  LMX, LMY, LVMX, pressure terms (PPX*, PPY*, PPZ* - absent in PAC2002),
  low-speed VXLOW reduction and the FZMIN/FZMAX/KPU/ALP/CAM input
  saturations of the commercial solvers.  Fz < 0 is clipped to 0.
  vx < 0: the book sign rules (sgn(Vcx) in alpha*, Dt, Dr, DHyphi, cos alpha')
  are applied literally - not validated.

Where LFZO enters  (the point the brief asked to check)
-------------------------------------------------------
LFZO enters ONLY through the scaled nominal load Fz0' = LFZO*FNOMIN (4.E1):
dfz = (Fz - Fz0')/Fz0' (4.E2a) everywhere, and the cornering stiffness

    KYalpha = PKY1 * Fz0' * sin(2*atan(Fz/(PKY2*Fz0'))) * (1 - PKY3*|gamma*|)
              * zeta3 * LKY                                          (4.E25)

which is IDENTICAL to the MF-Tyre 5.2 manual form written with the unscaled
FNOMIN = Fz0:  PKY1*Fz0*sin(2*atan(Fz/(PKY2*Fz0*LFZO)))*(1-PKY3|gy|)*LFZO*LKY
(MFeval comment "MF5.2 equations from the MF-Tyre equation manual"; the same
form is used in TNO-derived MF52 fitting scripts).  So LFZO appears exactly
twice: once as prefactor and once inside the arctan.  Writing Fz0' AND an
extra LFZO (as in the brief's draft formula) would count LFZO twice (LFZO**2
in the prefactor) - that is wrong; it is not what the book or MFeval do.
Hence KYalpha(LFZO=l)/KYalpha(1) = l*sin(2atan(Fz/(PKY2*l*Fz0)))/
sin(2atan(Fz/(PKY2*Fz0))) at equal Fz (printed by the self check).
KXkappa = Fz*(PKX1+PKX2*dfz)*exp(PKX3*dfz)*LKX (4.E15): LFZO only via dfz.
Aligning moment: the book uses R0/Fz0' in Dt0 (4.E42) and Fy/Fz0' in s
(4.E76); TNO/MFeval use FNOMIN there (MFeval: Dt with Fz0' then t*LFZO,
"empirically discovered" vs the TNO solver; s with Fz0 "paper A56").  This is
the only LFZO difference between the two variants.

Variants (differences only show for gamma != 0, kappa != 0 with alpha != 0
in Mz, LFZO != 1 or non-unit LMUX/LMUY)
--------------------------------------------------------------------------
"book"  (default):   alpha* = tan(alpha)sgn(Vcx), gamma* = sin(gamma);
    Dt0 = Fz*(R0/Fz0')*(QDZ1+QDZ2 dfz)*LTR*sgn(Vcx), Dt = Dt0*(1+QDZ3 g*+QDZ4 g*^2)
    s  = R0*(SSZ1 + SSZ2*Fy/Fz0' + (SSZ3+SSZ4 dfz)*g*)*LS
    alpha_eq = sqrt(alpha^2 + (KX/KY')^2 kappa^2)*sgn(alpha)   (4.E77/78)
    Mz = -t*Fy' + Mzr + s*Fx,  Fy' = Gyk(gamma=0)*Fy0(gamma=0, phi=0) (4.E71-74)
"mfeval52": MFeval Solver FITTYP==6, useMode 111 (TNO-validated by MFeval):
    alpha* = alpha, gamma* = gamma; Dt uses R0/FNOMIN and no sgn(Vcx);
    s uses FNOMIN and gamma; alpha_eq = atan(sqrt(tan^2(alpha)+(KX/KY')^2
    kappa^2))*sgn (paper A54/A55); Mz = -t*(Fy - SVyk) + Mzr + s*Fx (MF-Tyre 5.2
    manual) with SVyk evaluated with muy(gamma=0) as MFeval does; Fx0 is
    sign-flipped for vx<0 as in MFeval.
Common choices (both variants), with the resolution of ambiguities:
  * Dt camber factor (1 + QDZ3*g + QDZ4*g^2) with SIGNED g (PAC2002 / paper A60;
    MFeval found the book's |gamma*| does not match TNO); Bt camber factor
    (1 + QBZ4*g + QBZ5*|g|) (PAC2002 has QBZ4, QBZ5, no QBZ6).
  * lambda'_mu = A_MU*lambda/(1+(A_MU-1)*lambda) (4.E8) with A_MU = 1 (MFeval:
    "Amu = 1 gives perfect match with TNO"; book p.179 suggests 10).  No LMUV.
  * Camber scaling: LGAY = lambda_Kygamma multiplies only the camber-stiffness
    terms PHY3 (SHy) and PVY3/PVY4 (SVy); LGAZ = lambda_Kzgamma multiplies only
    the QDZ8/QDZ9 term of Dr (book mapping, as MFeval's LKYC/LKZC).  The
    MF-Tyre 5.2 manual instead uses gamma_y = gamma*LGAY / gamma_z = gamma*LGAZ
    in every camber term - identical when LGAY = LGAZ = 1.  LGAX is not used.
  * Dr (4.E47) = Fz R0 [(QDZ6+QDZ7 dfz) LRES zeta2 + (QDZ8+QDZ9 dfz) g* LGAZ zeta0]
    * LMUY* * sgn(Vcx) * cos(alpha) + zeta8 - 1, with the PHYSICAL alpha in
    cos(alpha) (MFeval writes cos(alpha*), which equals cos(alpha) in its TNO
    mode).  Mzr0 = Dr cos(Cr atan(Br alpha_r)) (no extra cos alpha'), Mzr =
    Dr cos(Cr atan(Br alpha_r,eq)) (4.E75).  Trail t carries cos(alpha').
  * E factors are clipped to <= 1 (Ex, Ey, Et, Exa, Eyk, EHyphi), as the book
    requires and MFeval/TNO do in their default (limit-check) mode.
  * eps = 1e-6 in Bx, By, KY' = KY + eps*sgn(KY) (4.E39) and Vc' = Vc + eps.
  * Mz0 reported in ``evaluate`` (pure side slip): book: -t0*Fy0(gamma=0) +
    Mzr0; mfeval52: -t0*Fy0 + Mzr0.  steady_state returns COMBINED Fx, Fy, Mz.

Turn slip (book section 4.3.3; only with ``turn_slip=True``; default all
zeta = 1 exactly, plain PAC2002)
-------------------------------------------------------------------------
Input phi_t = -psi_dot/Vcx [1/m] with psi_dot the ISO yaw rate (z up), i.e.
the same input column as MFeval; phi_t > 0 is a RIGHT-hand turn.  The spin
used in the zeta functions is phi = -phi_t (identical to MFeval's internal
phi for gamma = 0), so a left turn (phi > 0) acts like a positive camber
(book: the spin phi and gamma* enter through K_yRphi0 = K_ygamma0/(1-eps_gamma)).
  camber_spin=False (default): zeta0 = 1, camber stays in the ordinary PAC2002
    terms, zeta4 = 1 + SHyphi; => with phi_t = 0 every zeta is exactly 1 for any
    gamma and any turn-slip coefficients.
  camber_spin=True (book 4.76 / 4.83-4.84): phi = -phi_t + (1-eps_g)*Omega*
    sin(gamma)/Vc', Omega = vx*(1+kappa)/R0 (Re ~ R0 approximation), zeta0 = 0,
    zeta4 = 1 + SHyphi - SVygamma/KY'.  (MFeval uses the opposite sign for the
    camber part of phi; with that sign camber thrust would be reversed when
    zeta0 = 0, so the book/physical sign is used here - checked numerically in
    the self-check: camber thrust is reproduced through the spin path.)
Equations: zeta1 = cos(atan(Bxphi R0 phi)), Bxphi = PDXP1(1+PDXP2 dfz)cos(atan(
PDXP3 kappa)); zeta2 = cos(atan(Byphi(R0|phi| + PDYP4 sqrt(R0|phi|)))), Byphi =
PDYP1(1+PDYP2 dfz)cos(atan(PDYP3 tan(alpha))); zeta3 = cos(atan(PKYP1 R0^2
phi^2)); SHyphi = DHyphi sin(CHyphi atan(BHyphi R0 phi - EHyphi(...)))sgn(Vcx),
CHyphi = PHYP1, DHyphi = (PHYP2+PHYP3 dfz)sgn(Vcx), EHyphi = PHYP4 (<=1),
BHyphi = KyRphi0/(CHyphi DHyphi KYalpha0'), KyRphi0 = KYgamma0/(1-eps_g),
eps_g = PECP1(1+PECP2 dfz); KYgamma0 (PAC2002, linearised 4.E27/4.E29) =
(PHY3*KYalpha0 + Fz(PVY3+PVY4 dfz) lambda'_muy) LGAY;  zeta5 = cos(atan(QDTP1 R0
phi)) (Dt); zeta6 = cos(atan(QBRP1 R0 phi)) (Br); Mzphi_inf = QCRP1|muy| R0 Fz
sqrt(Fz/Fz0') LMP; CDrphi = QDRP1; DDrphi = Mzphi_inf/sin(pi/2 CDrphi);
KzgammaR0 = Fz R0 (QDZ8+QDZ9 dfz) LGAZ (MFeval has a typo QDZ8*QDZ9 here);
BDrphi = KzgammaR0/(CDrphi DDrphi (1-eps_g)); Drphi = DDrphi sin(CDrphi atan(
BDrphi R0 phi)) (spin phi, MFeval uses phi_t); Mzphi90 = Mzphi_inf (2/pi)
atan(QCRP2 R0 |phi_t|) Gyk; zeta7 = (2/pi) acos(Mzphi90/|Drphi|) (ratio
clipped to [-1,1]; 0/0 -> zeta7 = 1); zeta8 = 1 + Drphi.
Missing turn-slip coefficients default to the MFeval/TNO MF6.1 example-file
values: PDXP1=0.4 PDXP2=0 PDXP3=0 PKYP1=1 PDYP1=0.4 PDYP2=0 PDYP3=0 PDYP4=0
PHYP1=1 PHYP2=0.15 PHYP3=0 PHYP4=-4 PECP1=0.5 PECP2=0 QDTP1=10 QCRP1=0.2
QCRP2=0.1 QBRP1=0.1 QDRP1=1 (LMP=1).

Mirroring (side = -1)
---------------------
MF-Tyre / Adams Tire (TYRESIDE): using a property file on the other vehicle
side mirrors the characteristics with respect to slip angle zero (Adams Tire
docs "Left and right tires": conicity/ply-steer and asymmetry corrected):
    Fx_m(k, a, g, phi_t) =  Fx(k, -a, -g, -phi_t)
    Fy_m(k, a, g, phi_t) = -Fy(k, -a, -g, -phi_t)
    Mz_m(k, a, g, phi_t) = -Mz(k, -a, -g, -phi_t)
Camber stiffness (dFy/dgamma), cornering stiffness and trail are unchanged;
the offsets flip.  Equivalently (exactly, for these equations) the odd
coefficients change sign: PHY1 PHY2 PVY1 PVY2 PEY3 RBY3 RVY1 RVY2 RHX1 QHZ1
QHZ2 QBZ4 QDZ3 QDZ6 QDZ7 QEZ4 SSZ1 (and the ply-steer-like parts), while
PHY3 PVY3 PVY4 PEY4 RVY3 QHZ3 QHZ4 QBZ5 QDZ4 QDZ8 QDZ9 QEZ5 SSZ2-4 keep theirs.
"""

from __future__ import annotations

import math
import re

import numpy as np

__all__ = [
    "read_tir",
    "steady_state",
    "evaluate",
    "cornering_stiffness",
    "slip_stiffness",
    "TURN_SLIP_DEFAULTS",
]

EPS = 1e-6  # epsilon_x, epsilon_y, epsilon_K, epsilon_V  (MFeval value)
A_MU = 1.0  # digressive friction factor A_mu of 4.E8 (TNO/MFeval: 1)

_SCALING_KEYS = (
    "LFZO", "LCX", "LMUX", "LEX", "LKX", "LHX", "LVX", "LGAX", "LCY", "LMUY",
    "LEY", "LKY", "LHY", "LVY", "LGAY", "LTR", "LRES", "LGAZ", "LXAL", "LYKA",
    "LVYKA", "LS", "LSGKP", "LSGAL", "LGYR", "LMX", "LMY", "LVMX", "LMP",
)

TURN_SLIP_DEFAULTS = {
    "PDXP1": 0.4, "PDXP2": 0.0, "PDXP3": 0.0,
    "PKYP1": 1.0,
    "PDYP1": 0.4, "PDYP2": 0.0, "PDYP3": 0.0, "PDYP4": 0.0,
    "PHYP1": 1.0, "PHYP2": 0.15, "PHYP3": 0.0, "PHYP4": -4.0,
    "PECP1": 0.5, "PECP2": 0.0,
    "QDTP1": 10.0, "QCRP1": 0.2, "QCRP2": 0.1, "QBRP1": 0.1, "QDRP1": 1.0,
}

_REQUIRED = ("FNOMIN", "UNLOADED_RADIUS", "PCX1", "PDX1", "PKX1", "PCY1",
             "PDY1", "PKY1", "PKY2")

_NUM_RE = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eEdD][+-]?\d+)?$")


# --------------------------------------------------------------------------
# .tir reader
# --------------------------------------------------------------------------
def _parse_value(raw: str) -> float | str:
    v = raw.strip()
    if len(v) >= 2 and v[0] == v[-1] and v[0] in "'\"":
        return v[1:-1].strip()
    if _NUM_RE.match(v):
        return float(v.replace("D", "E").replace("d", "e"))
    return v.strip("'\"").strip()


def read_tir(path) -> dict[str, float | str]:
    """Minimal .tir parser.

    Sections ``[NAME]`` are tracked; lines ``KEY = value $ comment`` are
    stored with upper-case keys.  Values are floats when numeric, otherwise
    strings with the quotes removed.  Lines starting with ``$``, ``!`` or
    ``{`` and lines without ``=`` (e.g. the [SHAPE] table) are skipped.
    Every entry is also stored as ``"SECTION.KEY"``; for the flat key a
    numeric value wins over a string one (e.g. [UNITS] MASS='kg' versus
    [INERTIA] MASS=9.3).
    """
    out: dict[str, float | str] = {}
    section = ""
    with open(path, encoding="utf-8", errors="replace") as fh:
        for line in fh:
            s = line.strip()
            if not s or s[0] in "$!{":
                continue
            if s.startswith("["):
                section = s[1:s.index("]")].strip().upper() if "]" in s else s[1:].upper()
                continue
            if "=" not in s:
                continue
            key, rest = s.split("=", 1)
            key = key.strip().upper()
            if not key:
                continue
            # strip the '$ comment' (outside quotes)
            val_chars = []
            quote = None
            for ch in rest:
                if quote:
                    if ch == quote:
                        quote = None
                elif ch in "'\"":
                    quote = ch
                elif ch == "$":
                    break
                val_chars.append(ch)
            value = _parse_value("".join(val_chars))
            if value == "":
                continue
            if section:
                out[section + "." + key] = value
            old = out.get(key)
            if old is None or isinstance(value, float) or not isinstance(old, float):
                out[key] = value
    return out


class _C:
    """Coefficient accessor: scaling -> 1, turn slip -> TURN_SLIP_DEFAULTS,
    required keys -> KeyError, anything else missing -> 0."""

    def __init__(self, p):
        self._p = p

    def __getattr__(self, name):
        p = self._p
        if name in p and isinstance(p[name], (int, float)):
            return float(p[name])
        if name in _SCALING_KEYS:
            return 1.0
        if name in TURN_SLIP_DEFAULTS:
            return TURN_SLIP_DEFAULTS[name]
        if name in _REQUIRED:
            raise KeyError(f"required tyre parameter {name} missing")
        return 0.0

    def has(self, name):
        return name in self._p and isinstance(self._p[name], (int, float))


def _sgn(x):
    """sign with sgn(0) = +1 (book / MFeval singularity convention)."""
    return np.where(x >= 0.0, 1.0, -1.0)


def _mf(B, C, D, E, x):
    bx = B * x
    return D * np.sin(C * np.arctan(bx - E * (bx - np.arctan(bx))))


def _mfcos(B, C, E, x):
    bx = B * x
    return np.cos(C * np.arctan(bx - E * (bx - np.arctan(bx))))


def _lam_gamma(c, new, old):
    return getattr(c, new) if c.has(new) else (getattr(c, old) if c.has(old) else 1.0)


# --------------------------------------------------------------------------
# closed-form stiffnesses
# --------------------------------------------------------------------------
def cornering_stiffness(p, fz, gamma=0.0, gamma_star=None):
    """KYalpha (4.E25), zeta3 = 1.  gamma* = sin(gamma) unless gamma_star given."""
    c = _C(p)
    fz = np.asarray(fz, dtype=np.float64)
    gs = np.sin(np.asarray(gamma, dtype=np.float64)) if gamma_star is None else gamma_star
    fz0p = c.LFZO * c.FNOMIN
    return (c.PKY1 * fz0p * np.sin(2.0 * np.arctan(fz / (c.PKY2 * fz0p)))
            * (1.0 - c.PKY3 * np.abs(gs)) * c.LKY)


def slip_stiffness(p, fz):
    """KXkappa (4.E15)."""
    c = _C(p)
    fz = np.asarray(fz, dtype=np.float64)
    fz0p = c.LFZO * c.FNOMIN
    dfz = (fz - fz0p) / fz0p
    return fz * (c.PKX1 + c.PKX2 * dfz) * np.exp(c.PKX3 * dfz) * c.LKX


# --------------------------------------------------------------------------
# model
# --------------------------------------------------------------------------
def evaluate(p, fz, kappa, alpha, gamma=0.0, vx=10.0, phi_t=0.0, side=+1, *,
             turn_slip=False, camber_spin=False, variant="book"):
    """Full steady-state evaluation; returns a dict of numpy arrays."""
    if variant not in ("book", "mfeval52"):
        raise ValueError("variant must be 'book' or 'mfeval52'")
    m52 = variant == "mfeval52"
    c = _C(p)

    arrs = np.broadcast_arrays(*[np.asarray(v, dtype=np.float64)
                                 for v in (fz, kappa, alpha, gamma, vx, phi_t, side)])
    fz, kappa, alpha, gamma, vx, phi_t, side = [np.array(a, dtype=np.float64) for a in arrs]
    if np.any((side != 1.0) & (side != -1.0)):
        raise ValueError("side must be +1 or -1")
    # mirroring: evaluate the file's tyre at (-alpha, -gamma, -phi_t), flip Fy, Mz
    alpha = side * alpha
    gamma = side * gamma
    phi_t = side * phi_t
    fz = np.maximum(fz, 0.0)

    # ---------------- basic quantities (4.E1 - 4.E8) ----------------------
    Fz0 = c.FNOMIN
    Fz0p = c.LFZO * Fz0                                  # 4.E1
    dfz = (fz - Fz0p) / Fz0p                             # 4.E2a
    R0 = c.UNLOADED_RADIUS
    sv = _sgn(vx)
    if m52:
        a_s = alpha.copy()
        g_s = gamma.copy()
    else:
        a_s = np.tan(alpha) * sv                         # 4.E3
        g_s = np.sin(gamma)                              # 4.E4
    Vsy = vx * np.tan(alpha)
    Vc = np.sqrt(vx * vx + Vsy * Vsy)
    Vcp = Vc + EPS                                       # 4.E6a
    cos_ap = vx / Vcp                                    # 4.E6  cos(alpha')
    lmux_s, lmuy_s = c.LMUX, c.LMUY                      # 4.E7 (no LMUV)
    lmux_p = A_MU * lmux_s / (1.0 + (A_MU - 1.0) * lmux_s)  # 4.E8
    lmuy_p = A_MU * lmuy_s / (1.0 + (A_MU - 1.0) * lmuy_s)
    lkyg = _lam_gamma(c, "LGAY", "LKYC")
    lkzg = _lam_gamma(c, "LGAZ", "LKZC")
    one = np.ones_like(fz)

    # ---------------- turn slip: spin and zeta factors --------------------
    if turn_slip:
        eps_g = c.PECP1 * (1.0 + c.PECP2 * dfz)          # 4.90
        phi = -phi_t
        if camber_spin:
            omega_over_vc = vx * (1.0 + kappa) / (R0 * Vcp)
            phi = phi + (1.0 - eps_g) * np.sin(gamma) * omega_over_vc   # 4.76
            zeta0 = 0.0 * one
        else:
            zeta0 = one.copy()
        Bxp = c.PDXP1 * (1.0 + c.PDXP2 * dfz) * np.cos(np.arctan(c.PDXP3 * kappa))
        zeta1 = np.cos(np.arctan(Bxp * R0 * phi))                       # 4.105
        Byp = c.PDYP1 * (1.0 + c.PDYP2 * dfz) * np.cos(np.arctan(c.PDYP3 * np.tan(alpha)))
        r0phi = R0 * np.abs(phi)
        zeta2 = np.cos(np.arctan(Byp * (r0phi + c.PDYP4 * np.sqrt(r0phi))))  # 4.77
        zeta3 = np.cos(np.arctan(c.PKYP1 * R0 * R0 * phi * phi))        # 4.79
        zeta5 = np.cos(np.arctan(c.QDTP1 * R0 * phi))                   # 4.91
        zeta6 = np.cos(np.arctan(c.QBRP1 * R0 * phi))                   # 4.102
    else:
        eps_g = 0.0 * one
        phi = 0.0 * one
        zeta0 = zeta1 = zeta2 = zeta3 = zeta5 = zeta6 = one

    # ---------------- pure longitudinal Fx0 (4.E9 - 4.E18) ----------------
    Cx = c.PCX1 * c.LCX                                                 # 4.E11
    mux = (c.PDX1 + c.PDX2 * dfz) * (1.0 - c.PDX3 * gamma ** 2) * lmux_s  # 4.E13
    Dx = mux * fz * zeta1                                               # 4.E12
    Kxk = fz * (c.PKX1 + c.PKX2 * dfz) * np.exp(c.PKX3 * dfz) * c.LKX   # 4.E15
    Bx = Kxk / (Cx * Dx + EPS * _sgn(Dx))                               # 4.E16
    SHx = (c.PHX1 + c.PHX2 * dfz) * c.LHX                               # 4.E17
    SVx = fz * (c.PVX1 + c.PVX2 * dfz) * c.LVX * lmux_p * zeta1          # 4.E18
    kx = kappa + SHx                                                    # 4.E10
    Ex = (c.PEX1 + c.PEX2 * dfz + c.PEX3 * dfz ** 2) * (1.0 - c.PEX4 * _sgn(kx)) * c.LEX
    Ex = np.minimum(Ex, 1.0)                                            # 4.E14
    Fx0 = _mf(Bx, Cx, Dx, Ex, kx) + SVx                                 # 4.E9
    if m52:
        Fx0 = np.where(vx < 0.0, -Fx0, Fx0)

    # ---------------- pure lateral Fy0 (4.E19 - 4.E30) --------------------
    def fy0_block(gs, use_ts):
        z0 = zeta0 if use_ts else one
        z2 = zeta2 if use_ts else one
        z3 = zeta3 if use_ts else one
        ky_base = c.PKY1 * Fz0p * np.sin(2.0 * np.arctan(fz / (c.PKY2 * Fz0p)))
        Kya = ky_base * (1.0 - c.PKY3 * np.abs(gs)) * z3 * c.LKY        # 4.E25
        Kya0 = ky_base * z3 * c.LKY                                     # gamma = 0
        SVyg = fz * (c.PVY3 + c.PVY4 * dfz) * gs * lkyg * lmuy_p * z2    # camber part of 4.E29
        Kyg0 = (c.PHY3 * Kya0 + fz * (c.PVY3 + c.PVY4 * dfz) * lmuy_p) * lkyg
        SHyp = 0.0 * one
        if use_ts and turn_slip:
            Kya_p = Kya + EPS * _sgn(Kya)
            Kya0_p = Kya0 + EPS * _sgn(Kya0)
            CHyp = c.PHYP1                                              # 4.85
            DHyp = (c.PHYP2 + c.PHYP3 * dfz) * sv                       # 4.86
            EHyp = min(c.PHYP4, 1.0)                                    # 4.87
            KyRp0 = Kyg0 / (1.0 - eps_g)                                # 4.89
            with np.errstate(divide="ignore", invalid="ignore"):
                BHyp = KyRp0 / (CHyp * DHyp * Kya0_p)                   # 4.88
                SHyp = _mf(BHyp, CHyp, DHyp, EHyp, R0 * phi) * sv       # 4.80
            SHyp = np.where(np.isfinite(SHyp), SHyp, 0.0)
            zeta4 = 1.0 + SHyp - (SVyg / Kya_p if camber_spin else 0.0)  # 4.84
        else:
            zeta4 = one
        SHy = (c.PHY1 + c.PHY2 * dfz) * c.LHY + c.PHY3 * gs * lkyg * z0 + zeta4 - 1.0  # 4.E27
        SVy = fz * (c.PVY1 + c.PVY2 * dfz) * c.LVY * lmuy_p * z2 + SVyg  # 4.E29
        ay = a_s + SHy                                                  # 4.E20
        Cy = c.PCY1 * c.LCY                                             # 4.E21
        muy = (c.PDY1 + c.PDY2 * dfz) * (1.0 - c.PDY3 * gs ** 2) * lmuy_s  # 4.E23
        Dy = muy * fz * z2                                              # 4.E22
        Ey = (c.PEY1 + c.PEY2 * dfz) * (1.0 - (c.PEY3 + c.PEY4 * gs) * _sgn(ay)) * c.LEY
        Ey = np.minimum(Ey, 1.0)                                        # 4.E24
        By = Kya / (Cy * Dy + EPS * _sgn(Dy))                           # 4.E26
        Fy0 = _mf(By, Cy, Dy, Ey, ay) + SVy                             # 4.E19
        return dict(Fy0=Fy0, muy=muy, Kya=Kya, Kya0=Kya0, Kyg0=Kyg0, SHy=SHy,
                    SVy=SVy, SVyg=SVyg, By=By, Cy=Cy, zeta4=zeta4, SHyp=SHyp)

    f = fy0_block(g_s, True)
    f0 = fy0_block(0.0 * g_s, False)          # gamma = 0, phi = 0 (for Mz)
    Fy0, muy, Kya, SHy, SVy, By, Cy = (f["Fy0"], f["muy"], f["Kya"], f["SHy"],
                                      f["SVy"], f["By"], f["Cy"])

    # ---------------- combined Fx (4.E50 - 4.E57) -------------------------
    Cxa = c.RCX1                                                        # 4.E55
    Exa = np.minimum(c.REX1 + c.REX2 * dfz, 1.0)                        # 4.E56
    SHxa = c.RHX1                                                       # 4.E57
    Bxa = (c.RBX1 + c.RBX3 * g_s ** 2) * np.cos(np.arctan(c.RBX2 * kappa)) * c.LXAL  # 4.E54
    a_sx = a_s + SHxa                                                   # 4.E53
    Gxa = _mfcos(Bxa, Cxa, Exa, a_sx) / _mfcos(Bxa, Cxa, Exa, SHxa)     # 4.E51/52
    Fx = Gxa * Fx0                                                      # 4.E50

    # ---------------- combined Fy (4.E58 - 4.E67) -------------------------
    def gyk_svyk(gs, mu, z2):
        DVyk = mu * fz * (c.RVY1 + c.RVY2 * dfz + c.RVY3 * gs) * np.cos(np.arctan(c.RVY4 * a_s)) * z2
        SVyk_ = DVyk * np.sin(c.RVY5 * np.arctan(c.RVY6 * kappa)) * c.LVYKA   # 4.E66/67
        SHyk = c.RHY1 + c.RHY2 * dfz                                    # 4.E65
        Eyk = np.minimum(c.REY1 + c.REY2 * dfz, 1.0)                    # 4.E64
        Cyk = c.RCY1                                                    # 4.E63
        Byk = (c.RBY1 + c.RBY4 * gs ** 2) * np.cos(np.arctan(c.RBY2 * (a_s - c.RBY3))) * c.LYKA  # 4.E62
        ks = kappa + SHyk                                               # 4.E61
        Gyk_ = _mfcos(Byk, Cyk, Eyk, ks) / _mfcos(Byk, Cyk, Eyk, SHyk)  # 4.E59/60
        return Gyk_, SVyk_

    Gyk, SVyk = gyk_svyk(g_s, muy, zeta2)
    Fy = Gyk * Fy0 + SVyk                                               # 4.E58

    # ---------------- aligning moment (4.E31 - 4.E49, 4.E71 - 4.E78) -----
    SHt = c.QHZ1 + c.QHZ2 * dfz + (c.QHZ3 + c.QHZ4 * dfz) * g_s          # 4.E35
    Kya_p = Kya + EPS * _sgn(Kya)                                       # 4.E39
    SHf = SHy + SVy / Kya_p                                             # 4.E38
    a_r = a_s + SHf                                                     # 4.E37
    a_t = a_s + SHt                                                     # 4.E34
    g_c = gamma if m52 else g_s     # camber variable in Bt, Dt (signed) and s
    Bt = ((c.QBZ1 + c.QBZ2 * dfz + c.QBZ3 * dfz ** 2)
          * (1.0 + c.QBZ4 * g_c + c.QBZ5 * np.abs(g_c)) * c.LKY / lmuy_s)  # 4.E40
    Ct = c.QCZ1                                                         # 4.E41
    if m52:
        Dt = (fz * (R0 / Fz0) * (c.QDZ1 + c.QDZ2 * dfz) * c.LTR
              * (1.0 + c.QDZ3 * g_c + c.QDZ4 * g_c ** 2) * zeta5)        # A60 * LFZO
    else:
        Dt0 = fz * (R0 / Fz0p) * (c.QDZ1 + c.QDZ2 * dfz) * c.LTR * sv   # 4.E42
        Dt = Dt0 * (1.0 + c.QDZ3 * g_c + c.QDZ4 * g_c ** 2) * zeta5      # 4.E43
    Et = ((c.QEZ1 + c.QEZ2 * dfz + c.QEZ3 * dfz ** 2)
          * (1.0 + (c.QEZ4 + c.QEZ5 * g_s) * (2.0 / math.pi) * np.arctan(Bt * Ct * a_t)))
    Et = np.minimum(Et, 1.0)                                            # 4.E44
    t0 = Dt * _mfcos(Bt, Ct, Et, a_t) * cos_ap                          # 4.E33

    # turn-slip moment factors zeta7, zeta8 (book 4.93 - 4.104)
    if turn_slip:
        Mzp_inf = np.maximum(c.QCRP1 * np.abs(muy) * R0 * fz * np.sqrt(fz / Fz0p) * c.LMP, EPS)
        CDrp = c.QDRP1
        DDrp = Mzp_inf / math.sin(0.5 * math.pi * CDrp)
        Kzgr0 = fz * R0 * (c.QDZ8 + c.QDZ9 * dfz) * lkzg
        BDrp = Kzgr0 / (CDrp * DDrp * (1.0 - eps_g))
        Drp = DDrp * np.sin(CDrp * np.arctan(BDrp * R0 * phi))
        Mzp90 = Mzp_inf * (2.0 / math.pi) * np.arctan(c.QCRP2 * R0 * np.abs(phi_t)) * Gyk
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(Mzp90 == 0.0, 0.0, Mzp90 / np.abs(Drp))
        ratio = np.clip(np.nan_to_num(ratio, nan=1.0, posinf=1.0, neginf=-1.0), -1.0, 1.0)
        zeta7 = (2.0 / math.pi) * np.arccos(ratio)
        zeta8 = 1.0 + Drp
    else:
        Drp = 0.0 * one
        zeta7 = zeta8 = one

    Dr = (fz * R0 * ((c.QDZ6 + c.QDZ7 * dfz) * c.LRES * zeta2
                     + (c.QDZ8 + c.QDZ9 * dfz) * g_s * lkzg * zeta0)
          * lmuy_s * sv * np.cos(alpha) + zeta8 - 1.0)                  # 4.E47
    Br = (c.QBZ9 * c.LKY / lmuy_s + c.QBZ10 * By * Cy) * zeta6          # 4.E45
    Cr = zeta7                                                          # 4.E46
    Mzr0 = Dr * np.cos(Cr * np.arctan(Br * a_r))                        # 4.E36
    Mz0 = -t0 * (Fy0 if m52 else f0["Fy0"]) + Mzr0                      # 4.E31/32

    # combined
    kk = (Kxk / Kya_p) ** 2 * kappa ** 2
    if m52:
        a_t_eq = np.arctan(np.sqrt(np.tan(a_t) ** 2 + kk)) * _sgn(a_t)  # A55
        a_r_eq = np.arctan(np.sqrt(np.tan(a_r) ** 2 + kk)) * _sgn(a_r)  # A54
        s = R0 * (c.SSZ1 + c.SSZ2 * (Fy / Fz0) + (c.SSZ3 + c.SSZ4 * dfz) * gamma) * c.LS  # A56
    else:
        a_t_eq = np.sqrt(a_t ** 2 + kk) * _sgn(a_t)                     # 4.E77
        a_r_eq = np.sqrt(a_r ** 2 + kk) * _sgn(a_r)                     # 4.E78
        s = R0 * (c.SSZ1 + c.SSZ2 * (Fy / Fz0p) + (c.SSZ3 + c.SSZ4 * dfz) * g_s) * c.LS  # 4.E76
    t = Dt * _mfcos(Bt, Ct, Et, a_t_eq) * cos_ap                        # 4.E73
    Mzr = Dr * np.cos(Cr * np.arctan(Br * a_r_eq))                      # 4.E75
    if m52:
        _, SVyk_g0mu = gyk_svyk(g_s, f0["muy"], one)
        Fy_prime = Fy - SVyk_g0mu                                       # MF-Tyre 5.2
    else:
        Gyk_g0, _ = gyk_svyk(0.0 * g_s, f0["muy"], one)
        Fy_prime = Gyk_g0 * f0["Fy0"]                                   # 4.E74
    Mz = -t * Fy_prime + Mzr + s * Fx                                   # 4.E71/72

    return {
        "fx": Fx, "fy": side * Fy, "mz": side * Mz,
        "fx0": Fx0, "fy0": side * Fy0, "mz0": side * Mz0,
        "kxk": Kxk, "kya": Kya, "kya0": f["Kya0"], "kyg0": f["Kyg0"],
        "mux": mux, "muy": muy, "gxa": Gxa, "gyk": Gyk, "svyk": side * SVyk,
        "shy": SHy, "svy": SVy, "shx": SHx, "svx": SVx,
        "t": t, "t0": t0, "mzr": side * Mzr, "mzr0": side * Mzr0, "s": s,
        "dfz": dfz, "alpha_star": a_s, "gamma_star": g_s, "cos_alpha_p": cos_ap,
        "phi": side * phi, "eps_gamma": eps_g, "drphi": side * Drp,
        "zeta0": zeta0 * one, "zeta1": zeta1 * one, "zeta2": zeta2 * one,
        "zeta3": zeta3 * one, "zeta4": f["zeta4"] * one, "zeta5": zeta5 * one,
        "zeta6": zeta6 * one, "zeta7": zeta7 * one, "zeta8": zeta8 * one,
    }


def steady_state(p, fz, kappa, alpha, gamma=0.0, vx=10.0, phi_t=0.0, side=+1, *,
                 turn_slip=False, camber_spin=False, variant="book"):
    """Combined-slip steady-state (Fx, Fy, Mz) [N, N, N m], ISO-W axes.

    fz [N] (>= 0), kappa [-], alpha [rad], gamma [rad], vx [m/s] (Vcx),
    phi_t [1/m] turn slip = -psi_dot/Vcx (only used with turn_slip=True),
    side = +1 (as in the file) or -1 (mirrored).  All array arguments are
    broadcast.  See the module docstring for conventions and variants.
    """
    r = evaluate(p, fz, kappa, alpha, gamma, vx, phi_t, side,
                 turn_slip=turn_slip, camber_spin=camber_spin, variant=variant)
    return r["fx"], r["fy"], r["mz"]


# --------------------------------------------------------------------------
# self check
# --------------------------------------------------------------------------
_DEFAULT_TIR = "/work/shared/data/tyres/315_80R22.5_PAC2002.tir"

_ASYM_KEYS = ("PHX1", "PHX2", "PVX1", "PVX2", "PHY1", "PHY2", "PVY1", "PVY2",
              "PEY3", "RBY3", "RVY1", "RVY2", "RHX1", "QHZ1", "QHZ2", "QBZ4",
              "QDZ3", "QDZ6", "QDZ7", "QEZ4", "SSZ1", "RHY1", "RHY2")


def _self_check(path=_DEFAULT_TIR):
    ok_all = True

    def report(name, ok, msg):
        nonlocal ok_all
        ok_all &= bool(ok)
        print(f"[{'PASS' if ok else 'FAIL'}] {name}: {msg}")

    p = read_tir(path)
    print(f"file: {path}")
    print(f"  FNOMIN={p['FNOMIN']} R0={p['UNLOADED_RADIUS']} PKY1={p['PKY1']} "
          f"PKY2={p['PKY2']} TYRESIDE={p.get('TYRESIDE')} FORMAT={p.get('PROPERTY_FILE_FORMAT')}")
    Fz = 35000.0
    h = 1e-6

    # 1. cornering stiffness, finite difference at alpha_y = 0 (kappa = 0)
    r = evaluate(p, Fz, 0.0, 0.0)
    Ky = float(r["kya"])
    a0 = -float(np.arctan(r["shy"]))          # alpha where alpha_y = 0
    d = (steady_state(p, Fz, 0.0, a0 + h)[1] - steady_state(p, Fz, 0.0, a0 - h)[1]) / (2 * h)
    d = float(d) * math.cos(a0) ** 2           # d/d(alpha*) with alpha* = tan(alpha)
    report("dFy/dalpha* at alpha_y=0 == KYalpha", abs(d / Ky - 1) < 1e-6,
           f"FD={d:.6e}  KYalpha={Ky:.6e}  (negative: ISO, Fy=-|K|alpha)")
    d0 = float((steady_state(p, Fz, 0.0, h)[1] - steady_state(p, Fz, 0.0, -h)[1]) / (2 * h))
    print(f"       dFy/dalpha at alpha=0 (file has SHy={float(r['shy']):.3e}): {d0:.6e}")
    psym = dict(p)
    for k in _ASYM_KEYS:
        psym[k] = 0.0
    ds = float((steady_state(psym, Fz, 0.0, h)[1] - steady_state(psym, Fz, 0.0, -h)[1]) / (2 * h))
    report("symmetric file: dFy/dalpha at alpha=0 == KYalpha", abs(ds / Ky - 1) < 1e-6,
           f"FD={ds:.6e}")

    # 2. slip stiffness
    rx = evaluate(p, Fz, 0.0, 0.0)
    k0 = -float(rx["shx"])
    dx = float((steady_state(p, Fz, k0 + h, 0.0)[0] - steady_state(p, Fz, k0 - h, 0.0)[0]) / (2 * h))
    Kx = float(slip_stiffness(p, Fz))
    report("dFx/dkappa at kappa_x=0 == KXkappa", abs(dx / Kx - 1) < 1e-6,
           f"FD={dx:.6e}  KX={Kx:.6e}")
    for fzz in (10000.0, 50000.0):
        kk = -float(evaluate(p, fzz, 0.0, 0.0)["shx"])
        dxx = float((steady_state(p, fzz, kk + h, 0.0)[0] - steady_state(p, fzz, kk - h, 0.0)[0]) / (2 * h))
        report(f"  same at Fz={fzz:.0f}", abs(dxx / float(slip_stiffness(p, fzz)) - 1) < 1e-6,
               f"FD={dxx:.6e}")

    # 3. LFZO
    p12 = dict(p)
    p12["LFZO"] = 1.2
    for fzz in (17500.0, 35000.0, 60000.0):
        k1 = float(evaluate(p, fzz, 0, 0)["kya"])
        k2 = float(evaluate(p12, fzz, 0, 0)["kya"])
        F0 = p["FNOMIN"]
        book = 1.2 * math.sin(2 * math.atan(fzz / (p["PKY2"] * 1.2 * F0))) / math.sin(
            2 * math.atan(fzz / (p["PKY2"] * F0)))
        report(f"LFZO=1.2 KY ratio Fz={fzz:.0f}", abs(k2 / k1 - book) < 1e-12,
               f"ratio={k2 / k1:.9f} book={book:.9f}")
        ps = dict(psym)
        ps["LFZO"] = 1.2
        dd = float((steady_state(ps, fzz, 0.0, h)[1] - steady_state(ps, fzz, 0.0, -h)[1]) / (2 * h))
        report(f"  FD (symmetric, LFZO=1.2) Fz={fzz:.0f}", abs(dd / k2 - 1) < 1e-6, f"FD={dd:.6e} K={k2:.6e}")

    # 4. Mz at alpha = 0 (symmetric) and sign
    mz_sym0 = float(steady_state(psym, Fz, 0.0, 0.0)[2])
    report("symmetric file Mz(alpha=0)", abs(mz_sym0) < 1e-9, f"Mz={mz_sym0:.3e} N m")
    mz_file0 = float(steady_state(p, Fz, 0.0, 0.0)[2])
    print(f"       file (asymmetric) Mz(alpha=0) = {mz_file0:.3f} N m")
    for adeg in (1.0, 2.0, 4.0):
        a = math.radians(adeg)
        fx_, fy_, mz_ = (float(v) for v in steady_state(p, Fz, 0.0, a))
        report(f"alpha=+{adeg:.0f} deg sign (Fy<0, Mz>0 restoring)", fy_ < 0 and mz_ > 0,
               f"Fy={fy_:.1f} N Mz={mz_:.1f} N m")
        mzm = float(steady_state(p, Fz, 0.0, -a)[2])
        report(f"alpha=-{adeg:.0f} deg Mz<0", mzm < 0, f"Mz={mzm:.1f} N m")

    # 5. combined slip
    a = math.radians(3.0)
    fyp = float(steady_state(p, Fz, 0.0, a)[1])
    for kap in (0.05, 0.1, -0.1):
        fyc = float(steady_state(p, Fz, kap, a)[1])
        report(f"|Fy(kappa={kap})| < |Fy(kappa=0)| at 3 deg", abs(fyc) < abs(fyp),
               f"{fyc:.1f} vs {fyp:.1f}")
    fxp = float(steady_state(p, Fz, 0.1, 0.0)[0])
    fxc = float(steady_state(p, Fz, 0.1, a)[0])
    report("|Fx(alpha=3deg)| < |Fx(alpha=0)| at kappa=0.1", abs(fxc) < abs(fxp), f"{fxc:.1f} vs {fxp:.1f}")

    # 6. turn slip reduces to plain model
    args = (Fz, np.array([0.0, 0.05, -0.1]), np.array([0.0, 0.05, -0.03]),
            np.array([0.0, 0.03, -0.05]))
    base = steady_state(p, *args)
    ts = steady_state(p, *args, turn_slip=True)
    same = all(np.array_equal(x, y) for x, y in zip(base, ts))
    report("turn_slip=True, phi_t=0 identical to plain (camber != 0)", same, "bit-exact")
    z = evaluate(p, *args, turn_slip=True)
    zs = [float(np.max(np.abs(z[f"zeta{i}"] - 1.0))) for i in range(9)]
    report("all zeta == 1 at phi_t=0", max(zs) == 0.0, f"max|zeta-1|={max(zs)}")
    tsc = steady_state(p, Fz, 0.0, 0.0, 0.0, 10.0, 0.0, turn_slip=True, camber_spin=True)
    report("camber_spin, gamma=0, phi_t=0 identical", all(float(x) == float(y) for x, y in
           zip(tsc, steady_state(p, Fz, 0.0, 0.0))), "")
    # camber routed through the spin (zeta0=0) reproduces the camber thrust
    g = 0.02
    fy_plain = float(steady_state(p, Fz, 0.0, 0.0, g)[1]) - float(steady_state(p, Fz, 0.0, 0.0, 0.0)[1])
    fy_spin = float(steady_state(p, Fz, 0.0, 0.0, g, turn_slip=True, camber_spin=True)[1]) - \
        float(steady_state(p, Fz, 0.0, 0.0, 0.0, turn_slip=True, camber_spin=True)[1])
    report("camber thrust via spin path has same sign/size", fy_plain * fy_spin > 0 and
           0.5 < fy_spin / fy_plain < 1.5, f"dFy plain={fy_plain:.1f} spin={fy_spin:.1f}")
    r_ts = evaluate(p, Fz, 0.0, 0.0, 0.0, 10.0, np.array([-0.05, 0.05]), turn_slip=True)
    print(f"       phi_t=-0.05/+0.05: Fy={r_ts['fy']}, Mz={r_ts['mz']}, zeta2={r_ts['zeta2']}, "
          f"zeta7={r_ts['zeta7']}")

    # 7. mirroring
    aa, gg = 0.03, 0.02
    fx1, fy1, mz1 = steady_state(p, Fz, 0.05, aa, gg, side=-1)
    fx2, fy2, mz2 = steady_state(p, Fz, 0.05, -aa, -gg)
    report("mirror: Fy_m(a,g) = -Fy(-a,-g), Mz likewise, Fx equal",
           fx1 == fx2 and fy1 == -fy2 and mz1 == -mz2, "")
    pm = dict(p)
    for k in _ASYM_KEYS[4:]:
        if k in ("RHY1", "RHY2"):
            continue
        pm[k] = -p.get(k, 0.0)
    pm["PHX1"], pm["PHX2"], pm["PVX1"], pm["PVX2"] = p["PHX1"], p["PHX2"], p["PVX1"], p["PVX2"]
    for var in ("book", "mfeval52"):
        A = np.array([0.3, 0.05, 0.0, -0.08])
        G = np.array([0.05, -0.03, 0.02, 0.0])
        K = np.array([0.0, 0.08, -0.2, 0.03])
        m1 = steady_state(p, Fz, K, A, G, side=-1, variant=var)
        m2 = steady_state(pm, Fz, K, A, G, variant=var)
        err = max(float(np.max(np.abs(x - y))) for x, y in zip(m1, m2))
        report(f"mirror == sign flip of odd coefficients ({var})", err < 1e-6, f"max diff {err:.2e}")
    fy_l = float(steady_state(p, Fz, 0.0, 0.0)[1])
    fy_r = float(steady_state(p, Fz, 0.0, 0.0, side=-1)[1])
    print(f"       conicity/ply-steer Fy(alpha=0): side+1 {fy_l:.2f} N, side-1 {fy_r:.2f} N")

    # 8. broadcasting + variant comparison
    fzv = np.array([10000.0, 35000.0, 60000.0])[:, None]
    av = np.radians(np.array([-6.0, -2.0, 0.0, 2.0, 6.0]))[None, :]
    fxv, fyv, mzv = steady_state(p, fzv, 0.05, av, 0.02)
    report("broadcast shape", fxv.shape == (3, 5) and fyv.dtype == np.float64, str(fxv.shape))
    b = evaluate(p, fzv, 0.05, av, 0.0)
    m = evaluate(p, fzv, 0.05, av, 0.0, variant="mfeval52")
    print("       book vs mfeval52 (gamma=0, kappa=0.05): max |dFx|=%.3g N |dFy|=%.3g N |dMz|=%.3g N m"
          % (np.max(np.abs(b["fx"] - m["fx"])), np.max(np.abs(b["fy"] - m["fy"])),
             np.max(np.abs(b["mz"] - m["mz"]))))

    print("\nsample values (book variant, Fz=35 kN, vx=10 m/s):")
    print("   kappa  alpha[deg] gamma[deg]        Fx [N]        Fy [N]     Mz [N m]")
    for kap, ad, gd in ((0.0, 0.0, 0.0), (0.1, 0.0, 0.0), (-0.1, 0.0, 0.0), (0.0, 2.0, 0.0),
                        (0.0, -5.0, 0.0), (0.0, 2.0, 3.0), (0.05, 4.0, 0.0), (-0.2, 8.0, 2.0)):
        fx_, fy_, mz_ = (float(v) for v in steady_state(p, Fz, kap, math.radians(ad), math.radians(gd)))
        print(f"  {kap:6.2f} {ad:10.1f} {gd:10.1f} {fx_:13.3f} {fy_:13.3f} {mz_:12.3f}")
    print(f"  KYalpha(Fz0)={Ky:.3f} N/rad  KXkappa(Fz0)={Kx:.3f} N")
    print("\nALL CHECKS PASSED" if ok_all else "\nSOME CHECKS FAILED")
    return ok_all


if __name__ == "__main__":
    import sys

    sys.exit(0 if _self_check(sys.argv[1] if len(sys.argv) > 1 else _DEFAULT_TIR) else 1)
