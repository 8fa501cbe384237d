"""The MuJoCo multibody reference plant (see issue: the multibody reference plant).

Not built yet: ``artic simulate --model mbd`` reports that it is unavailable.
"""

raise ImportError("the multibody plant is not implemented yet")
