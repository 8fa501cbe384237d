"""Compiling a spec while a Python passive callback serves other models.

A numpy plant installs a Python ``mjcb_passive``; MuJoCo's compiler ends with a
forward pass through that callback, which the bindings cannot serve for a model
that has no Python object yet. :func:`artic.mjcf.compiling.compile_spec` keeps the
callback out of the compilation without touching the process-global callback, so
a plant stepping on another thread keeps its tyre forces.
"""

from __future__ import annotations

import threading

import mujoco
import numpy as np
import pytest

from artic.mjcf.builder import build_model
from artic.mjcf.compiling import compile_spec
from artic.mjcf.interface import InitialState
from artic.plant import Plant


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


def _drive(plant: Plant, n: int) -> np.ndarray:
    plant.reset(InitialState(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -0.8, 0.05))
    out = []
    for _ in range(n):
        plant.step(0.01, 0.05, -0.8, 0.0)
        out.append(plant.data.qpos.copy())
    return np.array(out)


def test_a_numpy_plant_keeps_its_forces_while_another_thread_compiles(unloaded):
    # The race that made a validation run on two threads fail with "py_mjcb_passive
    # is null" when the compiled parts were absent: one thread compiled a model
    # (and switched the global callback off meanwhile) while the other stepped.
    with Plant(unloaded, backend="python") as p:
        alone = _drive(p, 150)
    stop = threading.Event()
    compiled = []

    def compile_meanwhile():
        while not stop.is_set():
            compiled.append(compile_spec(build_model(unloaded)))

    with Plant(unloaded, backend="python") as p:
        other = threading.Thread(target=compile_meanwhile)
        other.start()
        try:
            beside = _drive(p, 150)
        finally:
            stop.set()
            other.join()
    assert len(compiled) >= 2  # the compilations overlapped the steps
    # Bitwise: the same inputs give the same numbers, compilations or not.
    np.testing.assert_array_equal(beside, alone)
