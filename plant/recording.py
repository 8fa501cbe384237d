"""The plant's recording: the outputs beyond the signal schema, for drawings and plots.

:class:`Recording` is one of the parts :class:`artic.plant.plant.Plant` is made
of: the poses, steering and spin angles, contact points, tyre forces and slips
that a recording draws (:attr:`~Recording.extra_columns`), read now
(:meth:`~Recording.extras`) or gathered per sample by the compiled closed loop
(:meth:`~Recording.extras_gather`, :meth:`~Recording.extras_from_raw`).
"""

from __future__ import annotations

import numpy as np

from artic.mjcf import naming as nm
from artic.plant import closedloop


class Recording:
    """The extra outputs' columns, addresses and values (a part of ``Plant``)."""

    def _index_extras(self, lay, ends) -> None:
        """Addresses and column names of :meth:`extras`."""
        m = self.model
        names = [nm.TRACTOR, nm.TRAILER, *(nm.axle(a.axle.name) for a in lay.axles)]
        self._pose_bodies = np.array([m.body(b).id for b in names])
        self._spin_qpos = np.array([m.jnt_qposadr[m.joint(nm.spin(a.axle.name, s)).id]
                                    for a, s in ends])
        steered = [(a, s) for a, s in ends if a.axle.steered]
        self._steer_qpos = np.array([m.jnt_qposadr[m.joint(nm.steer(a.axle.name, s)).id]
                                     for a, s in steered], dtype=int)
        wheels = [f"{a.axle.name}.{s}" for a, s in ends]
        cols = [f"pose.{b}.{c}" for b in names for c in ("x", "y", "z", "qw", "qx", "qy", "qz")]
        cols += [f"steer.{a.axle.name}.{s}" for a, s in steered]
        cols += [f"spin.{w}" for w in wheels]
        for what in ("contact", "force"):
            cols += [f"{what}.{w}.{c}" for w in wheels for c in ("x", "y", "z")]
        cols += [f"slip.{w}" for w in wheels]
        cols.append("steer_torque")
        self.extra_columns: tuple[str, ...] = tuple(cols)
        self._gather: np.ndarray | None = None

    def extras(self) -> np.ndarray:
        """Outputs beyond the signal schema, for drawings and plots, in :attr:`extra_columns` order.

        - ``pose.BODY.{x,y,z,qw,qx,qy,qz}``: world position [m] and orientation
          (MuJoCo's w, x, y, z quaternion) of the tractor, the semitrailer and
          every axle body;
        - ``steer.AXLE.SIDE``: steering-hinge angle of each steered wheel [rad];
        - ``spin.AXLE.SIDE``: wheel spin angle [rad];
        - ``contact.AXLE.SIDE.{x,y,z}``: contact point, world frame [m];
        - ``force.AXLE.SIDE.{x,y,z}``: tyre force of the wheel end there from
          the last callback, world frame [N] (``z`` is the wheel load);
        - ``slip.AXLE.SIDE``: transient slip angle alpha of the tyre [rad];
        - ``steer_torque``: the front steering servo's actuator torque [N m].

        It is :meth:`extras_from_raw` of the values :meth:`extras_gather` names,
        read now; the compiled closed loop gathers the same values per sample.
        """
        d = self.data
        g = self.extras_gather()
        arrays = {"qpos": d.qpos, "xpos": d.xpos.ravel(), "xquat": d.xquat.ravel(),
                  "site_xpos": d.site_xpos.ravel(),
                  # the forces: where the compiled callback writes them, or the numpy one's
                  "userdata": (d.userdata if self.backend == "compiled"
                               else self.last_forces.ravel()),
                  "act": d.act,
                  "actuator_force": d.actuator_force, "zero": np.zeros(1)}
        raw = np.empty(len(g))
        for k, name in enumerate(closedloop.SOURCES):
            sel = g[:, 0] == k
            raw[sel] = arrays[name][g[sel, 1]]
        return self.extras_from_raw(raw[None, :])[0]

    def extras_gather(self) -> np.ndarray:
        """Where each raw value behind :meth:`extras` is read, shape (n_columns, 2).

        Row ``j`` is (index into :data:`artic.plant.closedloop.SOURCES`, index into
        that ``MjData`` array, flattened). The ``slip`` columns read the tread's
        lateral deflection, which :meth:`extras_from_raw` turns into a slip angle.
        """
        if self._gather is None:
            src = {n: k for k, n in enumerate(closedloop.SOURCES)}
            rows = []
            for b in self._pose_bodies:
                rows += [(src["xpos"], 3 * b + c) for c in range(3)]
                rows += [(src["xquat"], 4 * b + c) for c in range(4)]
            rows += [(src["qpos"], a) for a in self._steer_qpos]
            rows += [(src["qpos"], a) for a in self._spin_qpos]
            for h in self._hub:
                rows += [(src["site_xpos"], 3 * h), (src["site_xpos"], 3 * h + 1),
                         (src["zero"], 0)]
            rows += [(src["userdata"], j) for j in range(3 * self.n_wheels)]
            rows += [(src["act"], a) for a in self._act_v]
            rows.append((src["actuator_force"], self._servo[0]) if self._servo
                        else (src["zero"], 0))
            self._gather = np.array(rows, dtype=np.int32).reshape(-1, 2)
        return self._gather

    def extras_from_raw(self, raw: np.ndarray) -> np.ndarray:
        """:meth:`extras` rows from rows of the raw values of :meth:`extras_gather`.

        Parameters
        ----------
        raw : ndarray, shape (n_samples, n_columns)

        Returns
        -------
        ndarray, shape (n_samples, n_columns)
            The raw rows with each ``slip`` column's tread deflection [m]
            turned into the slip angle [rad] at that wheel's load.
        """
        out = np.array(raw, dtype=float, copy=True)
        nw = self.n_wheels
        s0 = len(self.extra_columns) - 1 - nw  # the slip columns, before steer_torque
        Fz = out[:, s0 - 3 * nw + 2:s0:3] / self._n_tyres  # force.*.z, per tyre
        v = out[:, s0:s0 + nw].copy()
        slip = out[:, s0:s0 + nw]
        for k, p in enumerate(self._tyres):  # each tyre file on its wheels
            w = self._tyre_set == k
            slip[:, w] = np.arctan(v[:, w] / p.sigma_alpha(np.maximum(Fz[:, w], p.FZMIN)))
        return out
