"""The generator's solver option: PGS for the CPU plant, Newton for MuJoCo Warp."""

from __future__ import annotations

import mujoco
import pytest

import artic
from artic.mjcf.builder import build_model
from artic.mjcf.compiling import compile_spec


def test_the_solver_is_the_only_difference():
    v = artic.load_vehicle("gosar2022-unloaded")
    pgs, newton = (compile_spec(build_model(v, solver=s)) for s in ("pgs", "newton"))
    assert pgs.opt.solver == mujoco.mjtSolver.mjSOL_PGS
    assert newton.opt.solver == mujoco.mjtSolver.mjSOL_NEWTON
    spec_pgs, spec_newton = build_model(v), build_model(v, solver="newton")
    spec_newton.option.solver = spec_pgs.option.solver
    compile_spec(spec_pgs)
    compile_spec(spec_newton)
    assert spec_pgs.to_xml() == spec_newton.to_xml()


def test_an_unknown_solver_is_refused_by_name():
    with pytest.raises(ValueError, match="solver 'cg': expected one of pgs, newton"):
        build_model(artic.load_vehicle("gosar2022-unloaded"), solver="cg")
