"""The truth's steering: a compliant column with play and servo assist, and a tie rod.

The plant under validation turns its left front wheel with a stiff position
servo (200 kN m/rad) and makes the right wheel follow a polynomial fitted to
the tie-rod trapezoid. The independent truth's steering is torque-driven
instead (``_truth_c.c`` computes it, :class:`Column` holds its numbers):

- the driver holds the steering wheel at ``delta_h``; the column's torsion
  bar, stiffness ``k_tb`` [N m/rad at the steering wheel], twists by
  ``i_s (delta_ref - delta_L)`` less the free play (``play``, at the steering
  wheel, a dead zone smoothed over ``play_smooth``), where
  ``delta_ref = (delta_h - offset) / i_s`` is the left-wheel angle the
  steering wheel stands for and ``delta_L`` the left wheel's;
- the steering gear turns the torsion-bar torque ``T_tb`` into ``i_s T_tb`` at
  the left knuckle, and the hydraulic assist adds ``T_a``, which follows
  ``assist_max tanh(boost i_s T_tb / assist_max)`` with the lag ``assist_tau``
  of the pump and valve;
- each kingpin has viscous friction ``c_kingpin``;
- a tie rod of axial stiffness ``k_rod`` and damping ``c_rod`` joins the
  steering arms (the trapezoid of :class:`artic.mjcf.linkage.Trapezoid`,
  solved exactly, not a fitted polynomial): the right wheel follows the left
  one through it;
- the steered wheels' kingpins lead their contact points by ``trail`` (the
  caster's), so lateral tyre forces turn the wheels against the column.

In its linear range, past the play, the column holds the left wheel with the
stiffness ``K = i_s^2 k_tb (1 + boost)`` (:meth:`Column.stiffness`): about
0.13 deg of road wheel per kN m with the numbers below, which a truck's
steering at rest shows. The values are ordinary for a heavy truck's
hydraulic steering: a torsion bar of 2 N m/deg, an assist eight times the
driver's torque up to 8 kN m, a 50 ms lag, caster of 4 deg.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from artic.mjcf.linkage import Trapezoid
from artic.mjcf.vehicle import Vehicle
from artic.validation.synthetic import truthc

TORSION_BAR = math.degrees(2.0)
"""Torsion-bar stiffness [N m/rad at the steering wheel]: 2 N m/deg."""

BOOST = 8.0
"""Assist torque over the driver's in the assist's linear range [-]."""

ASSIST_MAX = 8000.0
"""Largest assist torque at the knuckle [N m]: the relief valve's."""

ASSIST_TAU = 0.05
"""Lag of the assist [s]."""

KINGPIN_DAMPING = 3000.0
"""Viscous friction of each kingpin and of the gear's valve [N m s/rad]: with
the steering's inertia (about 40 kg m^2 per side) it damps the 12 Hz mode of
the column's stiffness at a ratio near 0.5."""

TIE_ROD_STIFFNESS = 4.0e5
"""The tie rod's stiffness seen at the right knuckle straight ahead [N m/rad]."""

TIE_ROD_DAMPING = 500.0
"""The tie rod's damping seen at the right knuckle straight ahead [N m s/rad].

The rod stretches when the knuckles turn against each other: with each
knuckle's inertia about its kingpin ``J`` (26.4 kg m^2 in the presets, most of
it the steering gear's armature), the stretch mode is
``J x'' = -2 k x - (2 c + c_kingpin) x'`` in ``x = delta_L - delta_R``, at
``sqrt(2 k / J) = 174 rad/s`` (28 Hz). This damper gives the rod alone a
damping ratio ``c / sqrt(2 k J) = 0.11``, a steel rod's on rubber-bushed ball
joints; the kingpins bring the mode to 0.44 (roots ``-76 +- 157i`` 1/s). It
was 4000 until the truth's step became 10 ms: a rod damped at 0.87 by itself,
which no rod is, overdamped the mode into a root at -333 1/s, a 3 ms relaxation
that explicit RK4 at 10 ms cannot hold (``h lambda = -3.3``, beyond -2.785;
``docs/design/truth.md``). The damper carries no static force: the truth's
equilibria and quasi-static steering are unchanged."""

CASTER = math.radians(4.0)
"""Caster angle of the steered axle: the contact point trails the kingpin by
``R0 tan(caster)``, 4 cm on a truck tyre."""

PLAY_SMOOTH = 0.02
"""Width over which the play's edges are rounded, over the play [-]."""


@dataclasses.dataclass(frozen=True)
class Column:
    """The numbers of the truth's steering (see the module docstring); SI units, radians."""

    i_s: float
    k_tb: float = TORSION_BAR
    play: float = 0.0
    play_smooth: float = 1e-4
    boost: float = BOOST
    assist_max: float = ASSIST_MAX
    assist_tau: float = ASSIST_TAU
    c_kingpin: float = KINGPIN_DAMPING
    track: float = 2.05
    arm: float = 0.25
    beta: float = 0.26
    rod: float = 1.92
    k_rod: float = 8.0e6
    c_rod: float = 8.0e4
    trail: float = 0.038

    @classmethod
    def of(cls, vehicle: Vehicle, play: float = 0.0) -> Column:
        """The column of ``vehicle``'s front axle, with its ``mbd`` steering ratio.

        Parameters
        ----------
        vehicle : Vehicle
            Its front axle's track, the wheelbase and the steering arm give the
            trapezoid; its tyre radius the trail.
        play : float
            Free play at the steering wheel [rad].
        """
        front = max((a for a in vehicle.tractor_axles if a.steered), key=lambda a: a.x)
        trap = Trapezoid(front.track, vehicle.L1, vehicle.steering.steering_arm)
        lever = trap.arm * math.cos(trap.beta)  # the rod's lever at the knuckle, straight ahead
        from artic.plant.tyre import TyreParams  # the radius of the front tyre

        r0 = TyreParams.from_tir(vehicle.tyre_file_for(front)).UNLOADED_RADIUS
        return cls(i_s=vehicle.steering_for("mbd").i_s, play=play,
                   play_smooth=max(PLAY_SMOOTH * play, 1e-4), track=trap.track, arm=trap.arm,
                   beta=trap.beta, rod=trap.rod, k_rod=TIE_ROD_STIFFNESS / lever ** 2,
                   c_rod=TIE_ROD_DAMPING / lever ** 2, trail=r0 * math.tan(CASTER))

    def stiffness(self) -> float:
        """The left wheel's stiffness against the steering wheel, past the play [N m/rad]."""
        return self.i_s ** 2 * self.k_tb * (1.0 + self.boost)

    def vector(self, ids: dict[str, int]) -> np.ndarray:
        """The block's column section: these numbers, then the model ids ``ids`` names."""
        names = truthc.column_names()
        values = {**dataclasses.asdict(self), **{k: float(v) for k, v in ids.items()}}
        missing = [n for n in names if n not in values]
        if missing:
            raise RuntimeError(f"the compiled truth's column needs {missing}: reinstall artic")
        return np.array([values[n] for n in names], dtype=float)

    def law(self, ref: float, dl: float, dr: float, wl: float = 0.0, wr: float = 0.0,
            assist: float = 0.0) -> dict[str, float]:
        """The compiled column's torques at one state (see :func:`truthc.column_law`)."""
        ids = dict.fromkeys(("slot", "steer_l_qpos", "steer_l_dof", "steer_r_qpos",
                             "steer_r_dof", "assist_act", "assist_ctrl"), 0)
        return truthc.column_law(self.vector(ids), ref, dl, dr, wl, wr, assist)
