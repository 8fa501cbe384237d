"""The model a truth configuration drives, and its driver's seat, without loading the plant.

The independent truth is the yard truth
(:class:`artic.validation.synthetic.yardtruth.YardTruth`: its own model,
tyres, column and loop) behind its own seat
(:class:`~artic.validation.synthetic.yardtruth.YardSeat`); making its logs
imports neither the plant (``artic.plant``) nor the validation harness
(``artic.validation.harness``), which the logs validate
(``tests/test_truth_driver.py`` reads the import graph). The structural and
legacy truths are the plant itself: they load it, and the harness's steering
map for their seat, when one is built. :class:`artic.validation.synthetic.truthplant.TruthPlant`,
the independent truth of the release before, stays in its module.
"""

from __future__ import annotations

from collections.abc import Mapping

from artic.mjcf.vehicle import Vehicle
from artic.validation.synthetic.actuation import TruthActuation

TIMESTEP = 5e-3
"""The independent truth's own step [s], RK4, on the reversing manoeuvres
(ramp steer in reverse, docking, parking), and its default. Pinned: the
plant's default step (:data:`artic.mjcf.builder.TIMESTEP`) can change without
the synthetic logs changing. At 10 ms these kinds' stops miss the convergence
targets (``benchmarks/bench_truth_convergence.py``, ``docs/design/truth.md``)."""

FORWARD_TIMESTEP = 1e-2
"""The independent truth's step [s] on the forward manoeuvres
(:data:`FORWARD_KINDS`): the log's sample. Every linearised mode of the truth
lies inside RK4's stability region at 10 ms (``tests/test_truth_timestep.py``),
and on every forward manoeuvre of the test matrix the truth at 10 ms is
within 1 cm, 0.05 deg and 1e-3 rad/s of itself at 1 ms, driven and replayed."""

FORWARD_KINDS = ("constant-steer", "slalom", "figure-8", "swept-sine")
"""The manoeuvre kinds the truth integrates at :data:`FORWARD_TIMESTEP`."""

PLANT_TRUTH_TIMESTEP = 5e-3
"""The structural and legacy truths' step [s]: they are the plant itself, and
keep the plain RK4 at 5 ms their logs were made with (the plant's spin mode
needs its fit, :mod:`artic.plant.spinmode`, to run at 10 ms)."""


def timestep_for(kind: str | None) -> float:
    """The independent truth's step [s] on a manoeuvre of ``kind``.

    :data:`FORWARD_TIMESTEP` for the :data:`FORWARD_KINDS`, :data:`TIMESTEP`
    for every other kind and for none (a docking benchmark's yard).
    """
    return FORWARD_TIMESTEP if kind in FORWARD_KINDS else TIMESTEP


def truth_model(vehicle: Vehicle, truth: Mapping, speed: str = "follow",
                timestep: float | None = None):
    """The vehicle of a truth configuration (see :mod:`artic.validation.synthetic.truth`).

    The independent truth is the yard truth
    (:class:`artic.validation.synthetic.yardtruth.YardTruth`: its own model,
    tyres, column and loop, at its own step; ``timestep`` does not apply to
    it); the structural and legacy truths are the plant itself, at their own
    step :data:`PLANT_TRUTH_TIMESTEP`. :class:`artic.validation.synthetic.truthplant.TruthPlant`,
    the independent truth of the release before, stays for its tests and benchmarks.

    Parameters
    ----------
    vehicle : Vehicle
        The truth's vehicle (with the yard's slope).
    truth : mapping
        The configuration, as drawn or as a log's metadata holds it.
    speed : str
        ``"pedals"`` for the truth's driver, ``"drive"`` for the legacy
        truth's, ``"follow"`` for the harness.
    timestep : float, optional
        Unused by the truths built here (kept for the callers' signature).
    """
    if truth.get("kind") == "independent":
        # Here, not at the top: MuJoCo and the truth's C loop load with the first truth built.
        from artic.validation.synthetic.yardtruth import YardSetup, YardTruth

        return YardTruth(vehicle, YardSetup.of(truth), speed)
    from artic.plant import Plant  # the plant's own truths: they are the plant

    return Plant(vehicle, speed=speed, timestep=PLANT_TRUTH_TIMESTEP, spin_fit=False)


def truth_actuation(model, steering, column, pedals=None, record: bool = False):
    """The driver's seat of a truth's model: what the generators drive.

    The yard truth has its own (:class:`artic.validation.synthetic.yardtruth.YardSeat`,
    its own steering gear; ``steering`` is not used); the plant's truths sit
    behind :class:`artic.validation.synthetic.actuation.TruthActuation` with the
    truth file's steering map (``steering``, a :class:`artic.mjcf.steering.Steering`).
    ``record``: keep the model's full
    state at every observation, in the seat's ``states`` (for the floor's
    open-loop predictions).
    """
    # Here, not at the top: MuJoCo and the truth's C loop load with the first truth built.
    from artic.validation.synthetic.yardtruth import YardSeat, YardTruth

    if isinstance(model, YardTruth):
        return YardSeat(model, column, pedals, record=record)
    return TruthActuation(model, steering, column, pedals, record=record)
