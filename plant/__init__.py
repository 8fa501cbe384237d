"""The MuJoCo multibody reference plant.

- :mod:`artic.plant.tyre`: the PAC2002 tyre with transient slip;
- :mod:`artic.plant.callback`: the process-wide passive-force dispatcher;
- :mod:`artic.plant.plant`: the plant behind the harness's model interface;
- :mod:`artic.plant.closedloop`: the harness's loop around the plant, compiled
  (``_loop_c.c``): a whole log in one call without the GIL;
- :mod:`artic.plant.standalone`: the plant as a standalone MJCF file, and :func:`load`;
- :mod:`artic.plant.curves`: steady-state tyre curves.
"""

from artic.plant.plant import Plant, PlantError, PlantWarning
from artic.plant.standalone import load

__all__ = ["Plant", "PlantError", "PlantWarning", "load"]
