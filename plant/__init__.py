"""The MuJoCo multibody reference plant.

- :mod:`plant.tyre`: the PAC2002 tyre with transient slip;
- :mod:`plant.callback`: the process-wide passive-force dispatcher;
- :mod:`plant.plant`: the plant behind the harness's model interface;
- :mod:`plant.closedloop`: the harness's loop around the plant, compiled
  (``_loop_c.c``): a whole log in one call without the GIL;
- :mod:`plant.standalone`: the plant as a standalone MJCF file, and :func:`load`;
- :mod:`plant.curves`: steady-state tyre curves.
"""

from plant.plant import Plant, PlantError, PlantWarning
from plant.standalone import load

__all__ = ["Plant", "PlantError", "PlantWarning", "load"]
