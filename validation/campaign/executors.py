"""Where the campaign's runs execute: :mod:`artic.validation.plumbing.executors`.

The executor lives in ``runs/``, beside the other parts the campaign shares,
because the docking benchmark's robustness sweeps use it too
(:mod:`artic.validation.docking.sweep`); this module keeps the campaign's name for it.
"""

from artic.validation.plumbing.executors import EXECUTORS, DaskOptions, cluster_executor

__all__ = ["EXECUTORS", "DaskOptions", "cluster_executor"]
