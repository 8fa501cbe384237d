"""Compile an ``MjSpec`` whatever passive-force callback the process has installed.

MuJoCo's compiler ends with a forward pass, and that pass calls the process-global
``mjcb_passive``. When that callback is a Python function (a plant on its numpy
tyre model, or a user's), the bindings cannot hand it the model being compiled,
which has no Python object yet, and the compilation fails. Switching the global
callback off around the compilation, as artic once did, is not safe while another
thread steps a plant: that plant's steps lose their tyre forces or raise. So the
compilation runs with the spec's springs and dampers disabled, the one condition
under which MuJoCo's passive stage returns before calling the callback, and the
compiled model gets the spec's own flags back. Nothing the compiler computes
(masses, inertias, constants, ``qpos_spring``) depends on those two flags; a test
compares the two compilations byte for byte.
"""

from __future__ import annotations

import mujoco

_PASSIVE_OFF = int(mujoco.mjtDisableBit.mjDSBL_SPRING) | int(mujoco.mjtDisableBit.mjDSBL_DAMPER)


def compile_spec(spec: mujoco.MjSpec) -> mujoco.MjModel:
    """``spec.compile()``, without calling the process's passive callback.

    Parameters
    ----------
    spec : mujoco.MjSpec
        The spec; its option flags are as they were afterwards.

    Returns
    -------
    mujoco.MjModel
        The compiled model, with the spec's ``opt.disableflags``.
    """
    flags = spec.option.disableflags
    spec.option.disableflags = flags | _PASSIVE_OFF
    try:
        model = spec.compile()
    finally:
        spec.option.disableflags = flags
    model.opt.disableflags = flags
    return model


def load_xml(path: str) -> mujoco.MjModel:
    """``mujoco.MjModel.from_xml_path(path)``, compiled by :func:`compile_spec`."""
    return compile_spec(mujoco.MjSpec.from_file(path))
