"""The plant's tyre forces in Python: the passive-force callback of ``backend="python"``.

:class:`TyreForces` is one of the parts :class:`artic.plant.plant.Plant` is made
of: the numpy reference of the compiled callback (:mod:`artic.plant.ctyre`), the
spin mode's fit to the step (:mod:`artic.plant.spinmode`) and the spin modes'
eigenvalues. See the plant's module docstring for what the callback computes.
"""

from __future__ import annotations

import mujoco
import numpy as np

from artic.plant import spinmode
from artic.plant.tyre import (
    deflection_rates,
    longitudinal_tread,
    rolling_resistance,
    transient_forces,
)


def _actuator_now(m: mujoco.MjModel, d: mujoco.MjData, a: int) -> float:
    """Actuator ``a``'s force as ``mj_fwdActuation`` will compute it from the state now.

    Fixed or affine gain and bias (the motors and servos of the plant); any
    other kind counts zero. The C callback's ``actuator_now``.
    """
    out = m.actuator_outadr[a]
    if m.actuator_dyntype[a] == mujoco.mjtDyn.mjDYN_NONE:
        x = d.ctrl[a]
        clamp = not m.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_CLAMPCTRL
        if m.actuator_ctrllimited[a] and clamp:
            x = min(max(x, m.actuator_ctrlrange[a, 0]), m.actuator_ctrlrange[a, 1])
    else:
        x = d.act[m.actuator_actadr[a] + m.actuator_actnum[a] - 1]
    gp, bp = m.actuator_gainprm[a], m.actuator_biasprm[a]
    length, speed = d.actuator_length[out], d.actuator_velocity[out]
    if m.actuator_gaintype[a] == mujoco.mjtGain.mjGAIN_FIXED:
        gain = gp[0]
    elif m.actuator_gaintype[a] == mujoco.mjtGain.mjGAIN_AFFINE:
        gain = gp[0] + gp[1] * length + gp[2] * speed
    else:
        return 0.0
    bias = 0.0
    if m.actuator_biastype[a] == mujoco.mjtBias.mjBIAS_AFFINE:
        bias = bp[0] + bp[1] * length + bp[2] * speed
    elif m.actuator_biastype[a] != mujoco.mjtBias.mjBIAS_NONE:
        return 0.0
    f = gain * x + bias
    if m.actuator_forcelimited[a]:
        f = min(max(f, m.actuator_forcerange[a, 0]), m.actuator_forcerange[a, 1])
    return f


class TyreForces:
    """The tyre forces of every wheel end in numpy, and the spin modes (a part of ``Plant``)."""

    def _wheel_kinematics(self, d: mujoco.MjData):
        """Per wheel end: hub position, heading, lateral axis, centre velocity, vertical hub.

        A wheel whose hub axis is vertical has no heading on the ground and
        gets no tyre force, as in the C callback.
        """
        pos = d.site_xpos[self._hub]
        R = d.site_xmat[self._hub].reshape(-1, 3, 3)
        hx = R[:, :, 0].copy()
        hx[:, 2] = 0.0
        norm = np.linalg.norm(hx, axis=1)
        flat = norm < 1e-9  # hub axis vertical: no heading, no tyre force (as in C)
        hx /= np.where(flat, 1.0, norm)[:, None]
        hy = np.column_stack([-hx[:, 1], hx[:, 0], np.zeros(len(hx))])
        cvel = d.cvel[self._hub_body]
        r = pos - d.subtree_com[self._root]
        w, v0 = cvel[:, :3], cvel[:, 3:]
        vel = v0 + np.column_stack([w[:, 1] * r[:, 2] - w[:, 2] * r[:, 1],
                                    w[:, 2] * r[:, 0] - w[:, 0] * r[:, 2],
                                    w[:, 0] * r[:, 1] - w[:, 1] * r[:, 0]])
        return pos, hx, hy, vel, flat

    def _passive(self, m: mujoco.MjModel, d: mujoco.MjData) -> None:
        pos, hx, hy, vel, flat = self._wheel_kinematics(d)
        rho = self.R0_w - pos[:, 2]
        Fz = np.where(rho > 0.0, self.k_t_w * rho - self.c_t_w * vel[:, 2], 0.0)
        Fz = np.maximum(Fz, 0.0)
        Vx = np.einsum("ij,ij->i", vel, hx)
        Vy = np.einsum("ij,ij->i", vel, hy)
        Re = self.R0_w - np.maximum(rho, 0.0) / 3.0
        Vsx = Vx - d.qvel[self._spin_dof] * Re
        u, v, phi = d.act[self._act_u], d.act[self._act_v], d.act[self._act_w]
        omega_z = d.cvel[self._hub_body][:, 2]  # the wheel's yaw rate about the ground normal
        Fx, Fy, Mz, My, du, dv, dphi, k_x, c_x, b_x = (np.empty(self.n_wheels)
                                                      for _ in range(10))
        for k, p in enumerate(self._tyres):  # each tyre file on its wheels
            w = self._tyre_set == k
            du[w], dv[w], dphi[w] = deflection_rates(p, Fz[w], Vx[w], Vsx[w], Vy[w],
                                                     omega_z[w], u[w], v[w], phi[w])
            Fx[w], Fy[w], Mz[w] = transient_forces(p, Fz[w], Vx[w], Vsx[w], Vy[w], omega_z[w],
                                                   u[w], v[w], phi[w],
                                                   self.vehicle.plant.tyre_moments)
            My[w] = rolling_resistance(p, Fz[w], Vx[w], Fx[w])
            k_x[w], c_x[w], b_x[w] = longitudinal_tread(p, Fz[w], Vx[w])
        n = self._n_tyres
        F = (n * Fx)[:, None] * hx + (n * Fy)[:, None] * hy
        F[:, 2] += n * Fz
        torque = (n * My)[:, None] * hy  # about the spin axis
        torque[:, 2] += n * Mz  # aligning and bore torque about the ground normal
        contact = pos.copy()
        contact[:, 2] = 0.0
        if self.spin_fit > 0.0:  # the spin mode, fitted to the step (as in the C callback)
            dFx, ddu = self._fit_spin(m, d, F, torque, contact, hx, Re, (k_x, c_x, b_x), du)
            Fx += dFx
            du += ddu
            F += (n * dFx)[:, None] * hx
        d.ctrl[self._tread_u] = np.where(flat, 0.0, du)
        d.ctrl[self._tread_v] = np.where(flat, 0.0, dv)
        d.ctrl[self._tread_w] = np.where(flat, 0.0, dphi)
        F[flat] = 0.0
        torque[flat] = 0.0
        self._last_forces = F
        for i in range(self.n_wheels):
            mujoco.mj_applyFT(m, d, F[i], torque[i], contact[i], int(self._wheel_body[i]),
                              d.qfrc_passive)

    def _fit_spin(self, m: mujoco.MjModel, d: mujoco.MjData, F: np.ndarray,
                  torque: np.ndarray, contact: np.ndarray, hx: np.ndarray, Re: np.ndarray,
                  tread: tuple[np.ndarray, np.ndarray, np.ndarray],
                  du: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:func:`artic.plant.spinmode.fit` of every wheel end, before its forces apply.

        The spin's rate counts the tyre's force and torque and everything else
        the passive stage knows on the spin dof: MuJoCo's own passive force, the
        applied force and the actuators on the joint (:meth:`_spin_actuator_forces`).
        A spin held by dry friction (the parking brake) is left to MuJoCo's solver.
        """
        spin = self._spin_dof
        q_x, Q = self._spin_forces(m, d, F, torque, contact, hx)
        inv_I = m.dof_invweight0[spin]
        f_spin = (Q + self._spin_actuator_forces(m, d) + d.qfrc_passive[spin]
                  + d.qfrc_applied[spin]) * inv_I
        mode = spinmode.Mode(inv_I, q_x, self._n_tyres, Re, *tread)
        dFx, ddu = spinmode.fit(m.opt.timestep, mode, f_spin, du, self.spin_fit)
        held = m.dof_frictionloss[spin] != 0.0
        return np.where(held, 0.0, dFx), np.where(held, 0.0, ddu)

    def _spin_forces(self, m: mujoco.MjModel, d: mujoco.MjData, F: np.ndarray,
                     torque: np.ndarray, contact: np.ndarray,
                     hx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Generalized forces on every wheel end's spin, per wheel end.

        Returns ``q_x``, that of one newton along ``hx`` at the contact [m], and
        ``Q``, that of its tyre force ``F`` and ``torque`` [N m].
        """
        spin = self._spin_dof
        jacp, jacr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
        q_x, Q = np.empty(self.n_wheels), np.empty(self.n_wheels)
        for i in range(self.n_wheels):
            mujoco.mj_jac(m, d, jacp, jacr, contact[i], int(self._wheel_body[i]))
            q_x[i] = jacp[:, spin[i]] @ hx[i]
            Q[i] = jacp[:, spin[i]] @ F[i] + jacr[:, spin[i]] @ torque[i]
        return q_x, Q

    def spin_modes(self) -> np.ndarray:
        """Eigenvalues of every wheel end's spin/tread mode now [1/s], shape ``(n_wheels, 2)``.

        :func:`artic.plant.spinmode.eigenvalues` of the spin dof's inertia, the
        contact point's lever on it and the tyre's tread at the wheel's load and
        speed now, fastest first: the model's own, whatever the step.
        """
        m, d = self.model, self.data
        pos, hx, _, vel, _ = self._wheel_kinematics(d)
        rho = self.R0_w - pos[:, 2]
        Fz = np.maximum(np.where(rho > 0.0, self.k_t_w * rho - self.c_t_w * vel[:, 2], 0.0), 0.0)
        Vx = np.einsum("ij,ij->i", vel, hx)
        Re = self.R0_w - np.maximum(rho, 0.0) / 3.0
        k_x, c_x, b_x = (np.empty(self.n_wheels) for _ in range(3))
        for k, p in enumerate(self._tyres):
            w = self._tyre_set == k
            k_x[w], c_x[w], b_x[w] = longitudinal_tread(p, Fz[w], Vx[w])
        contact = pos.copy()
        contact[:, 2] = 0.0
        zero = np.zeros_like(hx)
        q_x, _ = self._spin_forces(m, d, zero, zero, contact, hx)
        return spinmode.eigenvalues(m.dof_invweight0[self._spin_dof], q_x, self._n_tyres, Re,
                                    k_x, c_x, b_x)

    def _spin_actuator_forces(self, m: mujoco.MjModel, d: mujoco.MjData) -> np.ndarray:
        """Generalized force on each spin dof from the actuators on its joint.

        The drive and the brakes (the tread states' actuators have no gain),
        each as ``mj_fwdActuation`` will compute it: fixed or affine gain and
        bias, the control clamped to its range, the force to its.
        """
        q = np.zeros(self.n_wheels)
        # As ints: ``x in (enum, ...)`` compares enum == x, which is False for numpy's ints.
        joint_trn = (int(mujoco.mjtTrn.mjTRN_JOINT), int(mujoco.mjtTrn.mjTRN_JOINTINPARENT))
        for i, j in enumerate(m.dof_jntid[self._spin_dof]):
            for a in range(m.nu):
                if int(m.actuator_trntype[a]) in joint_trn and m.actuator_trnid[a, 0] == j:
                    q[i] += m.actuator_gear[m.actuator_outadr[a], 0] * _actuator_now(m, d, a)
        return q
