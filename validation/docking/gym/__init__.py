"""Docking for learning controllers: the benchmark behind Gymnasium's interface.

:mod:`.spaces` turns a controller's :class:`~artic.validation.docking.controllers.Observation`
into the environment's observation vector and an action in [-1, 1] into a
:class:`~artic.validation.docking.controllers.Command`; :mod:`.policy` is the
adapter that scores a policy function with ``artic dock --controller``;
:mod:`.episode` runs one docking run of :func:`artic.validation.docking.run.drive`
one command at a time; :mod:`.reward` is the shaped reward; :mod:`.env` is the
Gymnasium environment (``pip install "artic[gym]"``), registered by :mod:`artic.gym`;
:mod:`.vector` is its native vector environment (``make_vec``'s ``vector_entry_point``),
batched in one step on KIN by :mod:`.kinbatch` and on the Warp plant by :mod:`.warpbatch`.
"""
