"""Compiling a spec while a Python passive callback serves other models.

A numpy plant installs a Python ``mjcb_passive``; MuJoCo's compiler ends with a
forward pass through that callback, which the bindings cannot serve for a model
that has no Python object yet. :func:`artic.mjcf.compiling.compile_spec` keeps the
callback out of the compilation without touching the process-global callback, so
a plant stepping on another thread keeps its tyre forces (tested in
``test_callback_threads.py``).
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from artic.mjcf.builder import build_model
from artic.mjcf.compiling import compile_spec


def _bytes(m: mujoco.MjModel) -> bytes:
    buf = np.zeros(mujoco.mj_sizeModel(m), dtype=np.uint8)
    mujoco.mj_saveModel(m, None, buf)
    return buf.tobytes()


@pytest.fixture
def python_callback():
    calls = []
    saved = mujoco.get_mjcb_passive()
    mujoco.set_mjcb_passive(lambda m, d: calls.append(1))
    yield calls
    mujoco.set_mjcb_passive(saved)


def test_a_python_callback_breaks_the_plain_compilation(unloaded, python_callback):
    # The failure compile_spec exists for: if MuJoCo stopped calling the callback
    # from the compiler, this would pass and compile_spec could go.
    with pytest.raises(Exception, match="Python exception"):
        build_model(unloaded).compile()


def test_compile_spec_gives_the_plain_model_without_calling_the_callback(unloaded):
    plain = _bytes(build_model(unloaded).compile())  # no Python callback installed
    saved = mujoco.get_mjcb_passive()
    calls = []
    mujoco.set_mjcb_passive(lambda m, d: calls.append(1))
    try:
        spec = build_model(unloaded)
        flags = spec.option.disableflags
        model = compile_spec(spec)
    finally:
        mujoco.set_mjcb_passive(saved)
    assert calls == []
    assert spec.option.disableflags == flags == model.opt.disableflags
    # Byte for byte: the disabled springs and dampers changed nothing the compiler
    # computes, and the flags are the spec's again.
    assert _bytes(model) == plain
