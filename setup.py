"""Build hook for artic's compiled parts: the plant's C tyre callback and closed loop, the truth's.

Everything else is in pyproject.toml. The extension is compiled against the
headers that the mujoco wheel ships. It is optional: without a C compiler the
install goes on, and the plant falls back, with a warning, to the numpy tyre
model (see plant/ctyre.py).
"""

import os

from setuptools import Extension, setup


def mujoco_include() -> list[str]:
    """The include folder of the mujoco wheel in the build environment."""
    try:
        import mujoco
    except ImportError:  # no mujoco in the build environment: the build fails, optionally
        return []
    return [os.path.join(os.path.dirname(mujoco.__file__), "include")]


setup(
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
