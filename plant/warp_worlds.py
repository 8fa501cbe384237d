"""Some worlds of a :class:`~artic.plant.warp_plant.WarpPlant` at a time: reset them, or hold them.

MuJoCo Warp steps every world of a batch at once. A batch of environments
wants less: to place a few worlds at new starts while the others drive on
(an episode's reset), and to step a few worlds while the others wait (a
docked run settling while the others wait for their agents). :class:`Worlds`
does both without touching the other worlds' numbers:

- :meth:`Worlds.keep` copies every per-world array of the plant (MuJoCo Warp's
  data, its constraint rows, the controllers' state and the sensors'
  headings) aside, on the device;
- :meth:`Worlds.restore` copies the rows of the worlds asked for back, bit for bit;
- :meth:`Worlds.reset` places the worlds asked for at their starts, as
  :meth:`WarpPlant.reset <artic.plant.warp_plant.WarpPlant.reset>` places all:
  MuJoCo Warp's ``forward`` runs over the whole batch, and the other worlds
  are restored after it, so they go on as if nothing had happened.

Contacts are not per world (MuJoCo Warp lists them for the batch) and are
recomputed by every step; the plant's model has none that its worlds carry over.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import mujoco_warp as mjw
import numpy as np
import warp as wp

from artic.mjcf.errors import UserError
from artic.mjcf.interface import InitialState


@wp.kernel
def _restore_words(mask: wp.array(dtype=int), kept: wp.array2d(dtype=wp.int32),
                   out: wp.array2d(dtype=wp.int32)):
    w, j = wp.tid()
    if mask[w] != 0:
        out[w, j] = kept[w, j]


@wp.kernel
def _restore_bytes(mask: wp.array(dtype=int), kept: wp.array2d(dtype=wp.uint8),
                   out: wp.array2d(dtype=wp.uint8)):
    w, j = wp.tid()
    if mask[w] != 0:
        out[w, j] = kept[w, j]


@wp.kernel
def _set_rows(worlds: wp.array(dtype=int), rows: wp.array2d(dtype=float),
              out: wp.array2d(dtype=float)):
    i, j = wp.tid()
    out[worlds[i], j] = rows[i, j]


@wp.kernel
def _zero_state(worlds: wp.array(dtype=int), integral: wp.array(dtype=float),
                steer_limited: wp.array(dtype=int), failed: wp.array(dtype=int),
                fail_time: wp.array(dtype=float), outside: wp.array(dtype=int)):
    i = wp.tid()
    w = worlds[i]
    integral[w] = 0.0
    steer_limited[w] = 0
    failed[w] = 0
    fail_time[w] = 0.0
    outside[w] = 0


def _rows_view(a: wp.array, n: int) -> wp.array | None:
    """``a`` (first dimension ``n``) as ``(n, words)`` of 4 or 1 bytes; None if empty."""
    if a.size == 0 or a.ndim == 0 or a.shape[0] != n:
        return None
    if not a.is_contiguous:
        raise UserError(f"a per-world array of shape {a.shape} is not contiguous; the Warp "
                        "plant's worlds cannot be reset one by one with this MuJoCo Warp")
    row = a.strides[0]
    dtype = wp.int32 if row % 4 == 0 else wp.uint8
    width = row // (4 if dtype is wp.int32 else 1)
    return wp.array(ptr=a.ptr, dtype=dtype, shape=(n, width), device=a.device, copy=False)


def _per_world_arrays(obj, n: int) -> list[wp.array]:
    """The arrays of a MuJoCo Warp dataclass whose first dimension is the world."""
    out = []
    for f in dataclasses.fields(obj):
        a = getattr(obj, f.name)
        shape = getattr(f.type, "shape", None)
        if isinstance(a, wp.array) and shape and shape[0] == "nworld":
            out.append(a)
        elif dataclasses.is_dataclass(a) and f.name == "efc":
            out.extend(_per_world_arrays(a, n))
    return out


class Worlds:
    """Reset or hold some worlds of ``plant`` (a :class:`~artic.plant.warp_plant.WarpPlant`).

    Parameters
    ----------
    plant : WarpPlant
        The batch. Its per-world arrays are viewed, not copied, and a copy of
        them is kept aside on its device (about the data's size again).
    """

    def __init__(self, plant) -> None:
        self.plant = plant
        n = plant.n_worlds
        ctl = plant.ctl
        s = ctl.state
        arrays = [*_per_world_arrays(plant.d, n), s.integral, s.steer_limited, s.failed,
                  s.fail_time, ctl.psi, ctl.signals, ctl.command, plant._outside, plant._forces]
        with wp.ScopedDevice(plant.device):
            self._views = [v for v in (_rows_view(a, n) for a in arrays) if v is not None]
            self._kept = [wp.empty_like(v) for v in self._views]
            self._arrays = arrays  # the views do not hold their memory: these do

    def keep(self) -> None:
        """Copy every world's state aside (on the device)."""
        with wp.ScopedDevice(self.plant.device):
            for v, k in zip(self._views, self._kept, strict=True):
                wp.copy(k, v)

    def restore(self, mask: wp.array) -> None:
        """Put the worlds of ``mask`` (int per world, nonzero: restore) back as kept."""
        with wp.ScopedDevice(self.plant.device):
            for v, k in zip(self._views, self._kept, strict=True):
                kernel = _restore_words if v.dtype is wp.int32 else _restore_bytes
                wp.launch(kernel, dim=v.shape, inputs=[mask, k], outputs=[v])

    def reset(self, worlds: Sequence[int], initial: Sequence[InitialState],
              steady: bool = False) -> np.ndarray:
        """Place ``worlds`` at ``initial`` (one each); the other worlds go on untouched.

        As :meth:`WarpPlant.reset <artic.plant.warp_plant.WarpPlant.reset>` for those
        worlds: the host plant's state of the start, the controllers zeroed, MuJoCo
        Warp's ``forward``. Returns their signals, ``(len(worlds), 13)``, as
        :meth:`WarpPlant.observe <artic.plant.warp_plant.WarpPlant.observe>` gives them.

        Raises
        ------
        UserError
            For a world outside the batch, or not one start per world.
        """
        p = self.plant
        worlds = [int(w) for w in worlds]
        if len(initial) != len(worlds):
            raise UserError(f"initial: {len(initial)} starts for {len(worlds)} worlds; give one "
                            "per world")
        bad = [w for w in worlds if not 0 <= w < p.n_worlds]
        if bad:
            raise UserError(f"world {bad[0]}: not in the batch of {p.n_worlds} worlds; give "
                            f"worlds from 0 to {p.n_worlds - 1}")
        if not worlds:
            return np.zeros((0, 13))
        rows: dict[str, list] = {"qpos": [], "qvel": [], "act": [], "ctrl": [], "psi": []}
        done: dict = {}
        for w, s in zip(worlds, initial, strict=True):
            key = (int(p._variant[w]), s)
            if key not in done:
                host = p.hosts[key[0]]
                (host.reset_steady if steady else host.reset)(s)
                d = host.data
                done[key] = (d.qpos.copy(), d.qvel.copy(), d.act.copy(), d.ctrl.copy(),
                             host._psi.copy())
            for name, value in zip(rows, done[key], strict=True):
                rows[name].append(value)
        mask = np.ones(p.n_worlds, dtype=np.int32)
        mask[worlds] = 0  # the others are restored after the batch's forward
        d = p.d
        with wp.ScopedDevice(p.device):
            idx = wp.array(np.array(worlds, dtype=np.int32), dtype=int)
            self.keep()
            reset = np.zeros(p.n_worlds, dtype=bool)
            reset[worlds] = True
            mjw.reset_data(p.m, d, reset=wp.array(reset, dtype=bool))
            for name, out in (("qpos", d.qpos), ("qvel", d.qvel), ("act", d.act),
                              ("ctrl", d.ctrl), ("psi", p.ctl.psi)):
                block = np.asarray(rows[name], dtype=np.float32).reshape(len(worlds), -1)
                if block.shape[1]:
                    wp.launch(_set_rows, dim=block.shape, inputs=[
                        idx, wp.array(block, dtype=float)], outputs=[out])
            s = p.ctl.state
            wp.launch(_zero_state, dim=len(worlds), inputs=[idx], outputs=[
                s.integral, s.steer_limited, s.failed, s.fail_time, p._outside])
            mjw.forward(p.m, d)
            p.ctl.observe(p)
            signals = p.ctl.signals.numpy()[worlds].astype(float)
            self.restore(wp.array(mask, dtype=int))
        return signals
