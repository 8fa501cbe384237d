"""Build hook for artic's layout and compiled parts.

Everything else is in pyproject.toml. Two things need code:

- **The layout.** ``artic`` is the one import name, and its four sub-packages
  stay at the repository root as the design card names them: ``artic.mjcf`` is
  ``mjcf/``, ``artic.plant`` is ``plant/`` and so on (setuptools' package-dir
  mapping; a wheel stores them as ``artic/mjcf/...``). The packages are found
  here so that a new sub-folder needs no edit.
- **The compiled parts**: the plant's C tyre callback and closed loop, the
  truth's. They are compiled against the headers that the mujoco wheel ships,
  and are optional: without a C compiler the install goes on, and the plant
  falls back, with a warning, to the numpy tyre model (see plant/ctyre.py).
"""

import os

from setuptools import Extension, find_packages, setup

ROOMS = ("mjcf", "plant", "reduced", "validation")
"""The four folders at the root that are ``artic``'s sub-packages."""


def packages() -> list[str]:
    """``artic`` and every package under the four folders, as ``artic.<folder>...``."""
    found = find_packages(include=[*ROOMS, *(f"{room}.*" for room in ROOMS)])
    return ["artic", *(f"artic.{name}" for name in found)]


def mujoco_include() -> list[str]:
    """The include folder of the mujoco wheel in the build environment."""
    try:
        import mujoco
    except ImportError:  # no mujoco in the build environment: the build fails, optionally
        return []
    return [os.path.join(os.path.dirname(mujoco.__file__), "include")]


setup(
    packages=packages(),
    package_dir={"artic": "artic", **{f"artic.{room}": room for room in ROOMS}},
    ext_modules=[
        Extension(
            "artic.plant._tyre_c",
            sources=["plant/_tyre_c.c"],
            include_dirs=mujoco_include(),
            extra_compile_args=["-O2", "-fno-math-errno", "-std=c99"],
            optional=True,
        ),
        Extension(  # the harness's closed loop around the plant (plant/closedloop.py)
            "artic.plant._loop_c",
            sources=["plant/_loop_c.c"],
            include_dirs=mujoco_include(),
            extra_compile_args=["-O2", "-fno-math-errno", "-std=c99"],
            optional=True,
        ),
        Extension(  # the synthetic truth's own tyres and steering (validation/synthetic/)
            "artic.validation.synthetic._truth_c",
            sources=["validation/synthetic/_truth_c.c"],
            include_dirs=mujoco_include(),
            extra_compile_args=["-O2", "-fno-math-errno", "-std=c99"],
            optional=True,
        ),
    ]
)
