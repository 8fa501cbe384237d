"""A reduced model's state as the harness holds it, and the former class names.

:class:`artic.KIN` and :class:`artic.STM` (:mod:`artic.reduced.control`) are
state-space models: their methods take the state and return the next one.
The harness and the other loops that hold a model's state from step to step
(:mod:`artic.validation.harness`, the synthetic driver, the docking
estimator) wrap one in :class:`Driven`, which offers the calls of the model
protocol (:class:`artic.validation.models.Model`): ``reset``, ``step``,
``observe``, ``gamma``. ``artic.validation.models.driven`` does it for any
model.

``KinematicModel`` and ``SingleTrackModel``, the harness's classes before
KIN and the STM became one class each, are :class:`~artic.reduced.control.KIN`
and :class:`~artic.reduced.control.STM` under their former names: using them
warns (:class:`DeprecationWarning`).
"""

from __future__ import annotations

import warnings

import numpy as np

from artic.mjcf.interface import InitialState, wrap_angle
from artic.reduced.control import KIN, STM, ReducedModel

__all__ = ["Driven"]


class Driven:
    """A reduced model and its state: what the harness steps and observes.

    Parameters
    ----------
    model : ReducedModel
        :class:`~artic.reduced.control.KIN`, :class:`~artic.reduced.control.STM`
        or a subclass; its methods are what this steps
        (:meth:`~artic.reduced.control.ReducedModel.advance`) and observes
        (:meth:`~artic.reduced.control.ReducedModel.signals`).
    """

    budget_kind = "reduced"
    """What its runs count as in the process's budget of simulated time."""

    def __init__(self, model: ReducedModel) -> None:
        self.model = model
        self.name = model.name
        self.x = np.zeros(model.nstates)
        self._u1 = 0.0
        self._delta = 0.0

    def __repr__(self) -> str:
        return f"<Driven {self.model!r}>"

    def __getattr__(self, name: str):
        # The model's own attributes (params, labels, axle_velocities, ...) read through.
        if name == "model":
            raise AttributeError(name)
        return getattr(self.model, name)

    def reset(self, initial: InitialState) -> None:
        """Place the model at a log's first sample (:meth:`ReducedModel.initial_state`)."""
        self.x = np.asarray(self.model.initial_state(initial), dtype=float)
        self._u1 = initial.u1
        self._delta = initial.delta

    def step(self, dt: float, delta: float, u1: float, u1_dot: float) -> None:
        """Advance ``dt`` [s], ``delta`` [rad] held, the speed ramping from ``u1`` [m/s]."""
        self.x = self.model.advance(self.x, dt, delta, u1, u1_dot)
        self._u1 = u1 + u1_dot * dt
        self._delta = delta

    def observe(self, delta: float | None = None) -> np.ndarray:
        """Signals at the sensor points, in ``OBSERVATION`` order.

        Parameters
        ----------
        delta : float, optional
            Road-wheel angle about to be held [rad]; KIN's yaw rates follow it
            at once (the STM's velocities are states and do not jump). The
            last applied angle by default.
        """
        d = self._delta if delta is None else delta
        return self.model.signals(self.x, self.model._inputs(d, self._u1, 0.0))

    def compiled(self) -> tuple | None:
        """``(kind, x, P, s1, s2)`` for the harness's compiled loop, or ``None``.

        ``None`` where the model's class replaced what that loop computes
        (:meth:`ReducedModel.compiled`).
        """
        form = self.model.compiled()
        if form is None:
            return None
        kind, P, s1, s2 = form
        return kind, self.x.copy(), P, s1, s2

    def closed_loop(self) -> None:
        """No loop of its own: the harness runs :meth:`compiled`, or steps it."""
        return None

    def close(self) -> None:
        """Nothing to release: a reduced model holds only arrays."""

    @property
    def gamma(self) -> float:
        """Articulation angle [rad]."""
        return float(wrap_angle(float(self.x[3])))

    @property
    def tyre_forces(self) -> np.ndarray:
        """The STM's lateral force of every axle, tractor first [N]."""
        return self.model.tyre_forces(self.x)


_FORMER = {"KinematicModel": KIN, "SingleTrackModel": STM}


def __getattr__(name: str):
    if name in _FORMER:
        cls = _FORMER[name]
        warnings.warn(f"artic.{name} is artic.{cls.__name__} under its former name; use "
                      f"artic.{cls.__name__} (the same class; this name goes in a later "
                      "minor version)", DeprecationWarning, stacklevel=2)
        return cls
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
