"""Docking controllers: the interface, the built-in ones, and loading a user's.

``artic dock --controller NAME`` takes a built-in name from :data:`BUILTIN`,
or ``package.module:Class`` for any importable class with a no-argument
constructor and the interface of :class:`~artic.validation.docking.controllers.base.Controller`.

- :mod:`~artic.validation.docking.controllers.base`: the interface and a base class;
- :mod:`~artic.validation.docking.controllers.reference`: the reference controller,
  LQR on KIN about the plan;
- :mod:`~artic.validation.docking.controllers.adaptive`: the reference controller
  re-designed online on the identified semitrailer;
- :mod:`~artic.validation.docking.controllers.mpc`: MPCs designed on KIN and on the STM;
- :mod:`~artic.validation.docking.controllers.mppi`: sampling MPCs (MPPI) on KIN and
  on the STM, on their batched rollouts.
"""

from __future__ import annotations

import importlib
import importlib.util
import traceback

from artic.mjcf.errors import UserError
from artic.validation.docking.controllers.base import (
    Command,
    Controller,
    Observation,
    Task,
)

__all__ = ["BUILTIN", "Command", "Controller", "Observation", "Task", "load"]

BUILTIN: dict[str, tuple[str, str]] = {
    "reference": ("artic.validation.docking.controllers.reference:ReferenceController",
                  "follows the plan: LQR on KIN about the path, gain-scheduled with speed"),
    "reference-adaptive": ("artic.validation.docking.controllers.adaptive:"
                           "AdaptiveReferenceController",
                           "the reference re-designed online on the identified semitrailer "
                           "(--trailer unknown)"),
    "mpc-kin": ("artic.validation.docking.controllers.mpc:MPCKin",
                "MPC designed on KIN, the reference's cost (needs CasADi: artic[mpc])"),
    "mpc-stm": ("artic.validation.docking.controllers.mpc:MPCStm",
                "MPC designed on the STM, the reference's cost (needs CasADi: artic[mpc])"),
    "mppi-kin": ("artic.validation.docking.controllers.mppi:MPPIKin",
                 "sampling MPC (MPPI) on KIN: 1 024 steering sequences over 5 s, the "
                 "reference's cost, collisions and the articulation limit"),
    "mppi-stm": ("artic.validation.docking.controllers.mppi:MPPIStm",
                 "sampling MPC (MPPI) on the STM: 256 steering sequences over 5 s, the "
                 "reference's cost, collisions and the articulation limit"),
}
"""Built-in controllers: name -> (``module:Class``, one line for ``--list``)."""


def load(spec: str) -> type:
    """The controller class named by ``spec``: a :data:`BUILTIN` name or ``module:Class``.

    A class's :attr:`~artic.validation.docking.controllers.base.Controller.requires`
    (modules its runs import) are checked here, before any run starts.

    Raises
    ------
    UserError
        One line naming what is wrong with ``spec`` and what to give instead.
    """
    target = BUILTIN[spec][0] if spec in BUILTIN else spec
    if ":" not in target:
        raise UserError(f"--controller {spec!r}: not a built-in controller "
                         f"({', '.join(BUILTIN)}) nor package.module:Class")
    module, _, name = target.partition(":")
    try:
        mod = importlib.import_module(module)
    except ImportError as exc:
        raise UserError(f"--controller {spec!r}: cannot import {module!r} ({exc}); put its "
                         f"folder on PYTHONPATH") from None
    except KeyboardInterrupt:
        raise
    except BaseException as exc:  # noqa: BLE001 - a SyntaxError, a raise or sys.exit at import
        where = ""
        if isinstance(exc, SyntaxError) and exc.filename:
            where = f" at {exc.filename}:{exc.lineno}"
        else:
            tb = traceback.extract_tb(exc.__traceback__)
            if tb:
                where = f" at {tb[-1].filename}:{tb[-1].lineno}"
        text = " ".join(str(exc).split())
        raise UserError(f"--controller {spec!r}: importing module {module!r} failed{where} "
                         f"({type(exc).__name__}{': ' + text if text else ''}); fix the "
                         "module") from None
    cls = getattr(mod, name, None)
    if not isinstance(cls, type) or not callable(getattr(cls, "command", None)) \
            or not callable(getattr(cls, "reset", None)):
        raise UserError(f"--controller {spec!r}: {module} has no class {name!r} with "
                         f"reset(task) and command(obs) methods")
    for needed, how in getattr(cls, "requires", ()) or ():
        if importlib.util.find_spec(needed) is None:  # its runs would each fail: none starts
            raise UserError(f"--controller {spec!r}: needs {needed}, which is not installed: "
                            f"{how}")
    return cls
