"""The MuJoCo multibody reference plant.

Built so far: the PAC2002 tyre force model (:mod:`plant.tyre`); the
property-file reader is :mod:`mjcf.tir`. The plant model behind the
harness interface is not built yet.
"""
