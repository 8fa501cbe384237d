"""One docking run of :func:`~artic.validation.docking.run.drive`, one command at a time.

``drive`` asks its controller for a command every sample period; a learning
agent wants the opposite: to be given an observation and to hand back an
action. :class:`Episode` runs ``drive`` on a worker thread with a controller
that passes each :class:`~artic.validation.docking.controllers.Observation` to
the caller and waits for the caller's command. So the episode is the
benchmark's run itself (its plant, actuators, sensors and seeds, its failure
checks, its scores and its recording), not a copy of its loop: an agent that
commands what a controller would command gets that controller's ``dock.csv`` row.

The handover is two queues; the caller's thread and the run's never compute
at the same time. ``drive``'s real-time check is off (the agent's time between
observations is not a controller's compute time), and the row's compute times
measure the wait for the agent.
"""

from __future__ import annotations

import queue
import threading
from dataclasses import dataclass

from artic.validation.docking.controllers.base import Command, Controller, Observation, Task
from artic.validation.docking.run import Result, drive
from artic.validation.docking.scenarios import Scenario


class _Closed(KeyboardInterrupt):
    """The caller left the episode before it ended.

    :func:`~artic.validation.docking.run.drive` passes a ``KeyboardInterrupt`` on
    instead of failing the run with it, so an abandoned run is neither scored nor
    recorded (a recording of a run the caller threw away would be an empty file
    left in ``recording_dir``), and its plant is closed on the way out.
    """


@dataclass(frozen=True)
class Step:
    """What the run reports next: an observation to answer, or its end.

    Parameters
    ----------
    observation : Observation or None
        The sensors' report, to be answered with :meth:`Episode.send`; ``None``
        once the run has ended.
    result : Result or None
        The run's result (its ``row`` holds the scores) once it has ended.
    """

    observation: Observation | None
    result: Result | None


class Episode:
    """A docking run driven by its caller.

    Parameters
    ----------
    scen : Scenario
        The yard and its starts.
    vehicle : str
        Preset name or vehicle file.
    seed : int
        Which start (and which noise), as ``artic dock --seeds``.
    yard_model : str
        ``"mbd"`` (the plant) or ``"kin"`` (:func:`~artic.validation.docking.run.drive`).
    **options
        More keyword arguments for :func:`~artic.validation.docking.run.drive`
        (for example ``record``).

    Examples
    --------
    Reverse straight until the run times out or fails:

    >>> import artic
    >>> from artic.validation.docking.scenarios import scenario
    >>> from artic.validation.docking.gym.episode import Episode
    >>> episode = Episode(scenario("straight"), "gosar2022-unloaded", seed=0, yard_model="kin",
    ...                   timeout=3.0)
    >>> step = episode.start()
    >>> while step.result is None:
    ...     step = episode.send(artic.Command(episode.task.vehicle.steering.delta_h_offset, -1.0))
    >>> step.result.row["failure"].split(":")[0]
    'timeout'
    """

    def __init__(self, scen: Scenario, vehicle: str, seed: int, yard_model: str = "mbd",
                 **options) -> None:
        # The run and its caller take turns, so neither queue holds more than one item;
        # SimpleQueue's hand-over costs half of Queue's, a share of every step.
        self._to_run: queue.SimpleQueue = queue.SimpleQueue()
        self._to_caller: queue.SimpleQueue = queue.SimpleQueue()
        self.task: Task | None = None
        """The run's task (vehicle file, yard, plan, limits), known after :meth:`start`."""
        self._args = (scen, vehicle, seed)
        self._options = {"yard_model": yard_model, "realtime": False, **options}
        self._thread: threading.Thread | None = None
        self._closed = False

    def _controller(self) -> type[Controller]:
        episode = self

        class Caller(Controller):
            name = "caller"

            def reset(self, task: Task) -> None:
                super().reset(task)
                episode.task = task

            def command(self, obs: Observation) -> Command:
                episode._to_caller.put(Step(obs, None))
                cmd = episode._to_run.get()
                if cmd is None:
                    raise _Closed
                return cmd

        return Caller

    def _run(self) -> None:
        try:
            scen, vehicle, seed = self._args
            result = drive(scen, vehicle, self._controller(), seed, **self._options)
        except BaseException as exc:  # noqa: BLE001 - handed to the caller's thread
            self._to_caller.put(exc)
            return
        self._to_caller.put(Step(None, result))

    def _next(self) -> Step:
        got = self._to_caller.get()
        if isinstance(got, BaseException):
            self._thread = None
            raise got
        if got.result is not None:
            self._thread = None
        return got

    def start(self) -> Step:
        """Plan, place the plant and return the first observation (or the end)."""
        if self._thread is not None or self._closed:
            raise RuntimeError("an Episode starts once; make a new one")
        self._thread = threading.Thread(target=self._run, daemon=True, name="artic-episode")
        self._thread.start()
        return self._next()

    def send(self, cmd: Command) -> Step:
        """Answer the last observation with ``cmd``; the next observation or the end."""
        self.post(cmd)
        return self.receive()

    def post(self, cmd: Command) -> None:
        """Answer the last observation with ``cmd`` and return at once.

        The run computes its next sample on its own thread meanwhile (the plant's
        steps release the GIL), so episodes posted one after another step side by
        side; :meth:`receive` waits for what it reports.
        """
        if self._thread is None:
            raise RuntimeError("the episode is not waiting for a command (not started, or ended)")
        self._to_run.put(cmd)

    def receive(self) -> Step:
        """The next observation or the end, after :meth:`post`."""
        return self._next()

    def close(self) -> None:
        """Stop a run still waiting for a command, and wait for its thread."""
        thread, self._closed = self._thread, True
        if thread is None:
            return
        self._to_run.put(None)  # its controller raises _Closed: drive ends the run
        while thread.is_alive():
            try:
                self._to_caller.get(timeout=0.1)
            except queue.Empty:
                pass
        self._thread = None
