"""The docking benchmark: controllers dock the plant in a distribution centre's yard.

Rooms by job: :mod:`~artic.validation.docking.scenarios` (the yard and the
seeded starts), :mod:`~artic.validation.docking.geometry` (poses and
collisions), :mod:`~artic.validation.docking.planner` (a path onto the dock),
:mod:`~artic.validation.docking.linear` (KIN linearised, the LQR gains),
:mod:`~artic.validation.docking.sensing` (the sensors, sample by sample),
:mod:`~artic.validation.docking.controllers` (the interface and the
controllers), :mod:`~artic.validation.docking.run` (the closed loop on the
plant), :mod:`~artic.validation.docking.scores` (per run and the table),
:mod:`~artic.validation.docking.plots` (the final errors as a picture) and
:mod:`~artic.validation.docking.command` (``artic dock``).
"""
