"""Build hook for artic's layout and compiled parts.

Everything else is in pyproject.toml. Three things need code:

- **The layout.** ``artic`` is the one import name, and its four sub-packages
  stay at the repository root as the design card names them: ``artic.mjcf`` is
  ``mjcf/``, ``artic.plant`` is ``plant/`` and so on (setuptools' package-dir
  mapping; a wheel stores them as ``artic/mjcf/...``). The packages are found
  here so that a new sub-folder needs no edit.
- **The compiled parts**: the plant's C tyre callback and closed loop, the
  truth's. They are compiled against the headers that the mujoco wheel ships,
  and are optional: without a C compiler the install goes on, and the plant
  falls back, with a warning, to the numpy tyre model (see plant/ctyre.py).
- **numba's cache of KIN and the STM**, filled after the extensions are built
  (:class:`BuildExt`), so that a reduced model's first call after install
  loads compiled code instead of compiling it for seconds (reduced/precompile.py
  says where numba keeps it and when it is used).
"""

import os
import subprocess
import sys

from setuptools import Extension, find_packages, setup
from setuptools.command.build_ext import build_ext

ROOMS = ("mjcf", "plant", "reduced", "validation")
"""The four folders at the root that are ``artic``'s sub-packages."""


def packages() -> list[str]:
    """``artic`` and every package under the four folders, as ``artic.<folder>...``."""
    found = find_packages(include=[*ROOMS, *(f"{room}.*" for room in ROOMS)])
    return ["artic", *(f"artic.{name}" for name in found)]


SHARED_HEADER = "mjcf/extensions.h"
"""What the extensions share (the sealed block, their exports), included by each."""


def include_dirs() -> list[str]:
    """The shared header's folder, and the mujoco wheel's include folder (build environment)."""
    try:
        import mujoco
    except ImportError:  # no mujoco in the build environment: the build fails, optionally
        return ["mjcf"]
    return ["mjcf", os.path.join(os.path.dirname(mujoco.__file__), "include")]


class BuildExt(build_ext):
    """``build_ext``, then numba's cache of the reduced models (``artic.reduced.precompile``).

    It is filled where the installed package will read it: the checkout for
    an editable install (``reduced/__pycache__``), the build folder for a
    wheel (``artic/reduced/__pycache__``, which the wheel carries). Optional
    as the extensions are: where it fails (no numba in the build environment,
    ``ARTIC_NO_PRECOMPILE=1``), the install goes on and the first call compiles.
    """

    def run(self) -> None:
        """Build the extensions, then fill numba's cache."""
        super().run()
        if os.environ.get("ARTIC_NO_PRECOMPILE", "") not in ("", "0"):
            return
        root = os.path.dirname(os.path.abspath(__file__))
        editable = self.inplace or getattr(self, "editable_mode", False)
        where = root if editable else self.build_lib
        env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
        # Keep what the build environment put on the path (pip's isolated build
        # reaches its numba and numpy through PYTHONPATH), after the package.
        env["PYTHONPATH"] = os.pathsep.join(
            p for p in (os.path.abspath(where), os.environ.get("PYTHONPATH", "")) if p)
        print(f"artic: filling numba's cache of KIN and the STM under {where}")
        # A wheel's build folder holds artic/reduced/; a checkout holds reduced/, which
        # the editable install's finder maps only once installed, so the child maps it
        # as package-dir does (PathFinder looks the last part of the name up in root).
        code = ("import sys" if not editable else
                "import sys; from importlib.machinery import PathFinder\n"
                "class Rooms:\n"
                "    @staticmethod\n"
                "    def find_spec(name, path=None, target=None):\n"
                f"        if name in {tuple(f'artic.{r}' for r in ROOMS)!r}:\n"
                f"            return PathFinder.find_spec(name, [{root!r}])\n"
                "sys.meta_path.append(Rooms)\n"
                "pass")
        done = subprocess.run(
            [sys.executable, "-c", code + "; from artic.validation.plumbing.runtime import "
             "fill_install_cache; fill_install_cache()"], env=env, cwd=where, check=False)
        if done.returncode != 0:
            print("artic: numba's cache was not filled; a reduced model's first call compiles")


setup(
    cmdclass={"build_ext": BuildExt},
    packages=packages(),
    package_dir={"artic": "artic", **{f"artic.{room}": room for room in ROOMS}},
    ext_modules=[
        Extension(
            "artic.plant._tyre_c",
            sources=["plant/_tyre_c.c"],
            include_dirs=include_dirs(),
            depends=[SHARED_HEADER],
            extra_compile_args=["-O2", "-fno-math-errno", "-std=c99"],
            optional=True,
        ),
        Extension(  # the harness's closed loop around the plant (plant/closedloop.py)
            "artic.plant._loop_c",
            sources=["plant/_loop_c.c"],
            include_dirs=include_dirs(),
            depends=[SHARED_HEADER],
            extra_compile_args=["-O2", "-fno-math-errno", "-std=c99"],
            optional=True,
        ),
        Extension(  # the synthetic truth's own tyres and steering (validation/synthetic/)
            "artic.validation.synthetic._truth_c",
            sources=["validation/synthetic/_truth_c.c"],
            include_dirs=include_dirs(),
            depends=[SHARED_HEADER],
            extra_compile_args=["-O2", "-fno-math-errno", "-std=c99"],
            optional=True,
        ),
    ]
)
