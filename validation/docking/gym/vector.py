"""Many docking environments in one process: a native Gymnasium ``VectorEnv``.

``gymnasium.make_vec("artic.gym:artic/Dock-v0", num_envs=N,
vectorization_mode="vector_entry_point")`` returns a :class:`DockVectorEnv`:
``N`` :class:`~artic.validation.docking.gym.env.DockEnv` in one process, without
a worker process each (``artic/DockKIN-v0`` gets the batched
:class:`~artic.validation.docking.gym.kinbatch.KinVectorEnv` where it covers the
options, and ``backend="warp"`` the Warp plant's
:class:`~artic.validation.docking.gym.warpbatch.WarpDockVectorEnv`: :func:`vector_env`).
Every episode already runs its ``artic dock`` loop on a thread of its own
(:class:`~artic.validation.docking.gym.episode.Episode`); a vector step hands
each episode its action first (:meth:`DockEnv.post`) and then collects the
results (:meth:`DockEnv.receive`), so the episodes compute side by side: the
plant's MuJoCo steps and its compiled tyre callback run without the GIL
(:mod:`artic.plant.callback`), the Python around them takes turns.

Guarantees:

- **equality**: sub-environment ``i`` gives exactly what a single environment
  gives for the same seed and actions, as ``gymnasium.vector.SyncVectorEnv``
  does: ``reset(seed=s)`` seeds sub-environment ``i`` with ``s + i``, and the
  observations, rewards, ends and infos are those of ``SyncVectorEnv`` of single
  environments, bit for bit (the compute-time columns of ``info["scores"]``
  measure the wait for the agent, as in the single environment);
- **autoreset**: Gymnasium's ``AutoresetMode.NEXT_STEP`` (its default,
  ``metadata["autoreset_mode"]``): the step after a sub-environment's episode
  ended resets it, ignoring its action, and returns its first observation with
  reward 0 and neither end;
- **bad actions**: an action array of another shape than ``(N, 2)``, or a row
  that is not finite, is refused before anything is stepped, with one line
  naming the sub-environment: every episode goes on as if the call had not been
  made (:class:`~artic.mjcf.errors.UserError`);
- **copies**: the arrays returned are the caller's; the environments keep their own.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from artic.mjcf.errors import UserError
from artic.validation.docking.gym.env import DockEnv
from artic.validation.docking.gym.kinbatch import KinVectorEnv, batchable, checked_actions

BACKENDS = ("cpu", "warp")
"""The ``backend`` keywords of :func:`vector_env`."""


def vector_env(num_envs: int = 1, backend: str = "cpu", device: str | None = None,
               **kwargs: Any) -> VectorEnv:
    """``make_vec``'s ``vector_entry_point``: batched where it can be, else threaded.

    With ``backend="cpu"`` (the default):
    :class:`~artic.validation.docking.gym.kinbatch.KinVectorEnv` for the
    configurations :func:`~artic.validation.docking.gym.kinbatch.batchable` covers
    (``artic/DockKIN-v0`` with the full sensor set, unrecorded, ``timeout`` the only
    ``drive`` option), :class:`DockVectorEnv` for the others. Both give what the
    single environments give, bit for bit.

    With ``backend="warp"``, ``artic/Dock-v0`` on the Warp plant on ``device``
    (``"cuda"``, or ``"cpu"``, the default):
    :class:`~artic.validation.docking.gym.warpbatch.WarpDockVectorEnv`, equal to the
    single environments within the Warp plant's float32 precision
    (``pip install "artic[gpu]"``).

    Raises
    ------
    artic.mjcf.errors.UserError
        One line for another backend, a ``device`` without ``backend="warp"``, or
        ``backend="warp"`` without the ``gpu`` extra.
    """
    if backend not in BACKENDS:
        raise UserError(f"backend {backend!r}: expected 'cpu' (the default) or 'warp' "
                        "(artic/Dock-v0 on the Warp plant, pip install 'artic[gpu]')")
    if backend == "warp":
        try:
            from artic.validation.docking.gym.warpbatch import WarpDockVectorEnv
        except ImportError as exc:
            raise UserError(f"backend='warp': the gpu extra is not installed ({exc.name}); "
                            "pip install 'artic[gpu]', or leave backend out") from None
        return WarpDockVectorEnv(num_envs, device=device or "cpu", **kwargs)
    if device is not None:
        raise UserError(f"device {device!r}: only with backend='warp'; add backend='warp' "
                        "(artic/Dock-v0 on the Warp plant), or leave device out")
    if batchable(kwargs):
        return KinVectorEnv(num_envs, **kwargs)
    return DockVectorEnv(num_envs, **kwargs)


class DockVectorEnv(VectorEnv):
    """``num_envs`` docking environments stepped side by side in one process.

    Parameters
    ----------
    num_envs : int
        How many.
    **kwargs
        The keywords of :class:`~artic.validation.docking.gym.env.DockEnv`, for each.

    Notes
    -----
    Version history (as Gymnasium's environments keep one):

    - v0, 2026-12-06: ``gymnasium.make_vec(..., vectorization_mode="vector_entry_point")``
      makes it for ``artic/Dock-v0`` (and for ``artic/DockKIN-v0`` where the batched
      one does not apply): the episodes' runs step side by side on their threads,
      with ``NEXT_STEP`` autoreset.

    Examples
    --------
    >>> import gymnasium as gym
    >>> import numpy as np
    >>> envs = gym.make_vec("artic.gym:artic/Dock-v0", num_envs=2,
    ...                     vectorization_mode="vector_entry_point", scenario="straight")
    >>> observations, infos = envs.reset(seed=0)
    >>> type(envs.unwrapped).__name__, observations.shape, infos["start"].shape
    ('DockVectorEnv', (2, 17), (2,))
    >>> observations, rewards, terminated, truncated, infos = envs.step(
    ...     np.array([[0.0, -0.5], [0.1, -0.5]]))
    >>> rewards.shape, terminated.tolist()
    ((2,), [False, False])
    >>> envs.close()
    """

    metadata = {"render_modes": ["rerun"], "render_fps": 10,
                "autoreset_mode": AutoresetMode.NEXT_STEP}


    def close(self, **kwargs: Any) -> None:
        """Close every episode (Gymnasium's ``VectorEnv.close``; its docstring is not RST)."""
        super().close(**kwargs)
    def __init__(self, num_envs: int, **kwargs: Any) -> None:
        if isinstance(num_envs, bool) or not isinstance(num_envs, int | np.integer) \
                or num_envs < 1:
            raise UserError(f"num_envs {num_envs!r}: expected a positive integer")
        self.num_envs = int(num_envs)
        self.envs = [DockEnv(**kwargs) for _ in range(self.num_envs)]
        first = self.envs[0]
        self.render_mode = first.render_mode
        self.single_observation_space = first.observation_space
        self.single_action_space = first.action_space
        self.observation_space = batch_space(first.observation_space, self.num_envs)
        self.action_space = batch_space(first.action_space, self.num_envs)
        n = self.num_envs
        self._observations = np.zeros((n, *first.observation_space.shape), np.float64)
        self._rewards = np.zeros(n, np.float64)
        self._terminations = np.zeros(n, np.bool_)
        self._truncations = np.zeros(n, np.bool_)
        self._autoreset = np.zeros(n, np.bool_)

    def reset(self, *, seed: int | list[int | None] | None = None,
              options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict]:
        """Reset every sub-environment (or those of ``options["reset_mask"]``).

        ``seed=s`` seeds sub-environment ``i`` with ``s + i``; a list gives each its own.
        ``options`` go to every sub-environment's reset (``"start"``, ``"scenario"``).
        """
        n = self.num_envs
        if seed is None:
            seeds: list[int | None] = [None] * n
        elif isinstance(seed, int | np.integer) and not isinstance(seed, bool):
            seeds = [int(seed) + i for i in range(n)]
        else:
            seeds = list(seed)
            if len(seeds) != n:
                raise UserError(f"seed: a list of {len(seeds)} seeds for {n} environments; "
                                f"give {n}, one int (seeding s, s + 1, ...) or None")
        options = dict(options or {})
        mask = options.pop("reset_mask", None)
        if mask is None:
            mask = np.ones(n, np.bool_)
        else:
            mask = np.asarray(mask)
            if mask.shape != (n,) or mask.dtype != np.bool_ or not mask.any():
                raise UserError(f"options['reset_mask']: expected a boolean array of shape "
                                f"({n},) with at least one True; got shape {mask.shape}, "
                                f"dtype {mask.dtype}")
        infos: dict[str, Any] = {}
        for i in np.flatnonzero(mask):
            self._observations[i], info = self.envs[i].reset(seed=seeds[i], options=options)
            infos = self._add_info(infos, info, int(i))
        self._terminations[mask] = False
        self._truncations[mask] = False
        self._autoreset[mask] = False
        return self._observations.copy(), infos

    def step(self, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                 np.ndarray, dict]:
        """Hold each sub-environment's action for 0.1 s (resetting those that ended)."""
        n = self.num_envs
        a = checked_actions(actions, n, self._autoreset)
        stepping = [i for i in range(n) if not self._autoreset[i]]
        for i in stepping:  # every run computes its next 0.1 s meanwhile
            self.envs[i].post(a[i])
        infos: dict[str, Any] = {}
        for i in range(n):
            if self._autoreset[i]:
                self._observations[i], info = self.envs[i].reset()
                self._rewards[i] = 0.0
                self._terminations[i] = self._truncations[i] = False
            else:
                (self._observations[i], self._rewards[i], self._terminations[i],
                 self._truncations[i], info) = self.envs[i].receive()
            infos = self._add_info(infos, info, i)
        self._autoreset = self._terminations | self._truncations
        return (self._observations.copy(), self._rewards.copy(), self._terminations.copy(),
                self._truncations.copy(), infos)

    def render(self) -> None:
        """Nothing to draw now: with ``render_mode="rerun"`` each episode is recorded whole."""
        return None

    def close_extras(self, **kwargs: Any) -> None:
        """Stop every unfinished episode."""
        for env in self.envs:
            env.close()

    def call(self, name: str, *args: Any, **kwargs: Any) -> tuple:
        """Each sub-environment's attribute ``name`` (called with the arguments if callable)."""
        out = []
        for env in self.envs:
            value = getattr(env, name)
            out.append(value(*args, **kwargs) if callable(value) else value)
        return tuple(out)

    def get_attr(self, name: str) -> tuple:
        """Each sub-environment's attribute ``name``."""
        return self.call(name)

