"""The MuJoCo multibody reference plant.

Built so far: the tyre property file reader (:mod:`plant.tir`) and the
PAC2002 tyre force model (:mod:`plant.tyre`). The plant model behind the
harness interface is not built yet.
"""
