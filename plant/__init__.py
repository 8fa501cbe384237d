"""The MuJoCo multibody reference plant.

- :mod:`plant.tyre`: the PAC2002 tyre with transient slip;
- :mod:`plant.callback`: the process-wide passive-force dispatcher;
- :mod:`plant.plant`: the plant behind the harness's model interface.
"""

from plant.plant import Plant, PlantError, PlantWarning

__all__ = ["Plant", "PlantError", "PlantWarning"]
