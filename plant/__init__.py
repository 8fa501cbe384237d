"""The MuJoCo multibody reference plant.

- :mod:`artic.plant.tyre`: the PAC2002 tyre with transient slip;
- :mod:`artic.plant.callback`: the process-wide passive-force dispatcher;
- :mod:`artic.plant.plant`: the plant behind the harness's model interface, made of
  one part per job: :mod:`artic.plant.building` (its model, indices and tyre sets),
  :mod:`artic.plant.tyreforces` (the tyre forces in Python), :mod:`artic.plant.stepping`
  (resets, speed control, the step), :mod:`artic.plant.observing` (the signals) and
  :mod:`artic.plant.recording` (the outputs for drawings);
- :mod:`artic.plant.closedloop`: the harness's loop around the plant, compiled
  (``_loop_c.c``): a whole log in one call without the GIL, and a docking run's
  steps between two controller samples;
- :mod:`artic.plant.standalone`: the plant as a standalone MJCF file, and :func:`load`;
- :mod:`artic.plant.curves`: steady-state tyre curves;
- :mod:`artic.plant.warp_plant`: many plants at once on MuJoCo Warp (the ``gpu`` extra),
  with :mod:`artic.plant.warp_tyre` (the tyre as Warp kernels), :mod:`artic.plant.warp_control`
  (the steering, speed and divergence kernels), :mod:`artic.plant.warp_loop` (the
  harness's reversing feedback around it, on the device) and :mod:`artic.plant.warp_check`
  (the equivalence run against the C plant).
"""

from artic.plant.plant import Plant, PlantError, PlantWarning
from artic.plant.standalone import load

__all__ = ["Plant", "PlantError", "PlantWarning", "load"]
