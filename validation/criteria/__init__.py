"""The criteria beyond the paper's eqs. (8)-(10), and the statistics that qualify them.

Each module has one job: an articulation error, open-loop prediction errors,
dock errors, noise-robust normalisation, confidence intervals and paired
comparisons. The paper's criteria themselves are in :mod:`artic.validation.criteria.metrics`.
"""
