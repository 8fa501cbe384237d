"""The reference controller, adaptive: it re-designs itself on the identified semitrailer.

A yard tractor does not know the semitrailer it backs: its bogie may sit a metre
from where the vehicle file says, its fifth wheel elsewhere. The reference
controller (:mod:`~artic.validation.docking.controllers.reference`) is designed on
the file's KIN; this one runs the online identification
(:class:`~artic.validation.docking.identify.WheelbaseIdentifier`) on its own
signals and, once the identified effective wheelbase ``L2`` or fifth-wheel
position ``L1c`` departs from its current design by more than
:data:`REDESIGN_L2` or :data:`REDESIGN_L1C` (and at most every
:data:`REDESIGN_PERIOD`), re-designs on KIN of the identified semitrailer
(:func:`~artic.validation.docking.variants.vary_semitrailer` of the file with the
bogie and the fifth wheel moved to match):

- the LQR gains, tabulated over speed again on the identified KIN;
- the point it tracks reversing: the semitrailer's identified no-slip point,
  ``L2`` behind the kingpin, and the plan's path of that point (the kingpin's
  planned path is kept: the plan is where the yard wants the semitrailer);
- reversing, the plan's steering, corrected by the steady steering that holds the plan's
  articulation on the identified KIN less that on the file's
  (:func:`~artic.validation.docking.planner.steady_delta`): the feedforward the
  identified semitrailer needs to follow the planned articulation.

Until :data:`MIN_UPDATES` windows have updated the identification it is the
reference controller exactly.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from artic.mjcf.errors import UserError
from artic.reduced.control import KIN
from artic.validation.docking.controllers.base import Command, Observation, Task
from artic.validation.docking.controllers.reference import STANDSTILL, ReferenceController
from artic.validation.docking.identify import WheelbaseIdentifier
from artic.validation.docking.linear import GainSchedule
from artic.validation.docking.planner import HybridAStar, PlanningError, steady_delta
from artic.validation.docking.scenarios import Start
from artic.validation.docking.variants import effective_wheelbase, vary_semitrailer

REDESIGN_L2 = 0.01
"""Relative change of the identified ``L2`` that re-designs the controller [-]."""

REDESIGN_L1C = 0.03
"""Change of the identified ``L1c`` that re-designs the controller [m]."""

REDESIGN_PERIOD = 2.0
"""Least time between re-designs [s]: one costs a few gain tables."""

MIN_UPDATES = 30
"""Identification windows before the first re-design (3 s of informative motion)."""

GAMMA_REF_MAX = math.radians(40.0)
"""Largest articulation the law asks for reversing [rad]: the planner's own limit."""

REPLAN_L2 = 0.03
"""Relative difference of the identified ``L2`` from the one the plan was made for that
makes the controller plan again at its next cusp [-]."""

TRUST = (0.75, 1.3)
"""Range of the identified ``L2`` over the file's that the controller will design on [-];
outside it the identification is held to it."""


class AdaptiveReferenceController(ReferenceController):
    """The reference controller re-designed on the identified semitrailer (module docstring)."""

    name = "reference-adaptive"

    def reset(self, task: Task) -> None:
        """The reference's reset, and an identifier of its own from the file's semitrailer."""
        super().reset(task)
        self.identifier = WheelbaseIdentifier(task.vehicle)
        self.nominal_frames = self.frames
        self.nominal_refs = list(self.refs)
        self.design = (float(self.frames.P[2]), float(task.vehicle.L1c))
        self.L2_track = float(self.frames.P[2])
        self.redesigned_at = -math.inf
        self.redesigns = 0
        self.design_vehicle = None
        self.planned_for = float(self.frames.P[2])
        self.replans = 0
        self.cusps_seen: set[int] = set()

    def command(self, obs: Observation) -> Command:
        """Identify, re-design if the semitrailer is not the one designed on, then follow."""
        if self.identifier.update(obs.t, obs.signals) and \
                self.identifier.updates >= MIN_UPDATES and \
                obs.t - self.redesigned_at >= REDESIGN_PERIOD:
            L2_nom = float(self.nominal_frames.P[2])
            L2 = min(max(self.identifier.L2, TRUST[0] * L2_nom), TRUST[1] * L2_nom)
            L1c = self.identifier.L1c
            if abs(L2 - self.design[0]) > REDESIGN_L2 * self.design[0] or \
                    abs(L1c - self.design[1]) > REDESIGN_L1C:
                self._redesign(L2, L1c, obs.t)
        if self.waiting and abs(obs["v_x_1"]) < STANDSTILL and self.k not in self.cusps_seen:
            self.cusps_seen.add(self.k)
            if self.design_vehicle is not None and \
                    abs(self.design[0] - self.planned_for) > REPLAN_L2 * self.planned_for:
                self._replan(obs)
        return super().command(obs)

    def _replan(self, obs: Observation) -> None:
        """At a cusp, plan the rest again for the identified semitrailer, and follow that.

        From the rear's pose and the articulation by the sensors, with the
        task's planner (:class:`~artic.validation.docking.planner.HybridAStar`). A
        plan not found keeps the one followed. The wheel is turned to the new
        plan's first steering at standstill, as at any cusp.
        """
        x, y, psi_2 = self.rear(obs)
        start = Start(float(x), float(y), float(psi_2), obs["gamma"])
        try:
            plan = HybridAStar().plan(self.task.yard, self.design_vehicle, start)
        except PlanningError:
            return
        task = dataclasses.replace(self.task, vehicle=self.design_vehicle, plan=plan)
        delta = self.delta
        ReferenceController.reset(self, task)  # frames, paths and gains of the identified
        self.nominal_frames = self.frames
        self.nominal_refs = list(self.refs)
        self.L2_track = float(self.frames.P[2])
        self.planned_for = self.design[0]
        self.delta = delta
        self.k, self.waiting = -1, True  # refs[k + 1] is the new plan's first segment
        self.cusps_seen = {-1}
        self.replans += 1

    def _redesign(self, L2: float, L1c: float, now: float) -> None:
        """Gains, tracked point and feedforward on KIN of the identified semitrailer."""
        v0 = self.vehicle
        dk = L1c - v0.L1c
        # The bogie's shift that gives the identified effective wheelbase: l_0 grows
        # with the bogie's position at slightly less than one to one; two secant steps.
        e = L2 - float(self.nominal_frames.P[2])
        for _ in range(2):
            try:
                v = vary_semitrailer(v0, length_error_m=e, kingpin_error_m=dk)
            except UserError:  # a geometry the file's checks refuse: keep the design
                return
            e += L2 - effective_wheelbase(v)
        kin = KIN(v)
        w = self.weights or (None, None)
        self.schedule = {-1: GainSchedule(kin, -1, self.task.dt, w[0]),
                         1: GainSchedule(kin, 1, self.task.dt, w[1])}
        P_nom, P = self.nominal_frames.P, kin.P
        self.L2_track = float(P[2])
        refs = []
        for (d, p, g_ref, d_ref, s), seg in zip(self.nominal_refs, self.task.plan.segments,
                                                strict=True):
            if d < 0:
                xk, yk = self.nominal_frames.kingpin(seg.states)
                psi_2 = seg.states[:, 2] - seg.states[:, 3]
                p = np.column_stack([xk - self.L2_track * np.cos(psi_2),
                                     yk - self.L2_track * np.sin(psi_2), psi_2])
                s = np.r_[0.0, np.cumsum(np.hypot(*np.diff(p[:, :2], axis=0).T))]
                d_ref = d_ref + np.array([steady_delta(g, P) - steady_delta(g, P_nom)
                                          for g in g_ref])
            refs.append((d, p, g_ref, d_ref, s))
        self.refs = refs
        self.design_vehicle = v
        self.design = (L2, L1c)
        self.redesigned_at = now
        self.redesigns += 1

    def _point(self, obs: Observation, direction: int) -> np.ndarray:
        if direction < 0:  # the identified no-slip point, from the semitrailer's kingpin
            _, trailer = self.nominal_frames.unit_poses_of_signals(obs.signals)
            xk, yk, psi_2 = trailer[0]
            return np.array([xk - self.L2_track * math.cos(psi_2),
                             yk - self.L2_track * math.sin(psi_2), psi_2])
        return super()._point(obs, direction)

    def _limit(self, z: np.ndarray, direction: int, gamma_path: float,
               K: np.ndarray) -> np.ndarray:
        """Reversing, hold the articulation the offset and heading ask for to the plan's limit.

        In the cascade form of the law, ``-K z = -k_gamma (gamma - gamma_ref)`` (and the
        steering's own term) with ``gamma_ref = gamma_path - (k_y e_y + k_psi e_psi) / k_gamma``.
        Far off the path (a semitrailer that left the cusp elsewhere than the plan
        expected) ``gamma_ref`` grows without bound and the steering runs to the lock;
        here it is held within :data:`GAMMA_REF_MAX`, by scaling ``(e_y, e_psi)``.
        """
        if direction > 0 or K[2] == 0.0:
            return z
        ask = (K[0] * z[0] + K[1] * z[1]) / K[2]
        g_ref = gamma_path - ask
        held = min(max(g_ref, -GAMMA_REF_MAX), GAMMA_REF_MAX)
        if held == g_ref or ask == 0.0:
            return z
        out = z.copy()
        out[:2] *= (gamma_path - held) / ask
        return out
