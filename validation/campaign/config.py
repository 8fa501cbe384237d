"""What defines a campaign: one frozen object the command line builds and the stages read.

:class:`CampaignConfig` holds every choice of ``artic campaign`` (the models,
the seed and the trucks, the measurement chain, where it runs and where it
writes). It checks them when it is made, so that a bad option fails with one
line before anything is written, and it gives the key that tells a resumed
campaign's saved stage times from another campaign's (:meth:`CampaignConfig.key`).
The stages take their fields by name from it instead of a dozen positional
arguments.
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from artic.mjcf.errors import UserError
from artic.validation.campaign.executors import DaskOptions
from artic.validation.harness.loop import DEFAULT_GAIN
from artic.validation.synthetic.sensors import SensorModel
from artic.validation.synthetic.testmatrix import MATRIX, check_only, selected, tuning_set
from artic.validation.synthetic.truth import DEFAULT as DEFAULT_TRUTH

SENSORS = ("default", "ideal")
"""Names of the measurement chains ``--sensors`` accepts."""


@dataclass(frozen=True)
class CampaignConfig:
    """One campaign's choices (see :func:`artic.validation.campaign.main.run_campaign`).

    Parameters
    ----------
    out_dir : Path
        Output folder.
    models : tuple of str, optional
        Models to tune and validate; every model of the registry when ``None``
        (:func:`artic.validation.models.names`, registered ones included).
    seed : int
        Seed of the synthetic campaign (the first truck's with ``seeds > 1``).
    jobs : int, optional
        Processes for generation, threads for the plant; the number of cores
        when ``None``.
    only : tuple of str, optional
        Manoeuvre names or prefixes: a part of the campaign (tests, studies).
    gain : float
        Reversing feedback gain K [rad/rad].
    sweep_models : tuple of str
        Models in the gain sweep (the plant makes it long: 33 logs per gain).
    recordings : bool
        Write the Rerun recordings.
    executor : str
        Where generation and validation run: ``local`` or ``dask``
        (:mod:`artic.validation.campaign.executors`).
    scheduler : str, optional
        A Dask scheduler's address (a local cluster when omitted).
    dask : DaskOptions, optional
        The scheduler's timeout and TLS files.
    truth : str
        The synthetic campaign's truth (:mod:`artic.validation.synthetic.truth`).
    remeasure : bool
        Compute the efficiency again from the validation runs' times, even
        when an earlier run with the same key computed it.
    seeds : int
        Trucks: with more than one, a campaign per seed (``seed`` on) in
        ``out_dir/seed-K`` and the pooled results in ``out_dir``.
    closing : bool
        Print the closing tables and where the report is.
    sensors : str
        The logs' measurement chain: ``default`` (noisy; every log then has a
        noise-free twin) or ``ideal`` (the truth's own signals).
    drift : bool
        ``False`` stills the steering column's drifting zero.
    oracle : bool
        Run KIN, the STM and the plant also untuned with the truth's own
        parameters (:mod:`artic.validation.campaign.oracle`), on the validated
        logs: the rows ``kin-oracle``, ``stm-oracle``, ``mbd-oracle``.
    tuning : str
        Which forward manoeuvres every model is tuned on, none of them
        validated (:data:`artic.validation.synthetic.testmatrix.TUNING_SETS`):
        ``default`` (constant steers at 200 deg and 5 km/h and the tuning
        slaloms), ``slaloms`` (the tuning slaloms alone) or ``transient``
        (the tuning slaloms, the paper's slalom and its figure-8).

    Raises
    ------
    UserError
        One line naming the option: fewer than one truck, an unknown sensor
        chain, or an ``only`` that selects tuning manoeuvres alone.

    See Also
    --------
    artic.run_campaign : run it.

    Examples
    --------
    >>> from pathlib import Path
    >>> from artic import CampaignConfig
    >>> c = CampaignConfig(Path("out"), models=("kin",), only=["00-", "28-"], jobs=2)
    >>> c.only, c.resolved().models
    (('00-', '28-'), ('kin',))
    >>> c.key() == CampaignConfig(Path("out"), models=("kin",), only=("00-", "28-")).key()
    True

    ``artic.run_campaign(c)`` runs it.
    """

    out_dir: Path
    models: tuple[str, ...] | None = None
    seed: int = 0
    jobs: int | None = None
    only: tuple[str, ...] | None = None
    gain: float = DEFAULT_GAIN
    sweep_models: tuple[str, ...] = ("kin", "stm")
    recordings: bool = True
    executor: str = "local"
    scheduler: str | None = None
    dask: DaskOptions | None = field(default=None, compare=False)
    truth: str = DEFAULT_TRUTH
    remeasure: bool = False
    seeds: int = 1
    closing: bool = True
    sensors: str = "default"
    drift: bool = True
    oracle: bool = True
    tuning: str = "default"

    def __post_init__(self) -> None:
        # Sequences given as lists (the command line's, a user's) become tuples:
        # the object is frozen and hashable, and the key is the same either way.
        set_ = object.__setattr__
        set_(self, "out_dir", Path(self.out_dir))
        for name in ("models", "only", "sweep_models"):
            value = getattr(self, name)
            if value is not None:
                set_(self, name, tuple(value))
        if self.only is not None and not self.only:
            set_(self, "only", None)
        if self.seeds < 1:
            raise UserError(f"--seeds {self.seeds}: a campaign needs at least one truck")
        if self.sensors not in SENSORS:
            raise UserError(f"--sensors {self.sensors}: expected default or ideal")
        tuning_set(self.tuning)
        check_selection(self.only, self.tuning)

    def resolved(self) -> CampaignConfig:
        """The campaign with its defaults filled: every registered model, every core."""
        from artic.validation.models import names

        return dataclasses.replace(
            self, models=tuple(names() if self.models is None else self.models),
            jobs=self.jobs or os.cpu_count() or 1)

    def for_seed(self, seed: int, out_dir: Path) -> CampaignConfig:
        """One truck's campaign of a ``--seeds`` run, in ``out_dir``, without closing lines."""
        return dataclasses.replace(self, out_dir=Path(out_dir), seed=seed, seeds=1,
                                   closing=False)

    def sensor_model(self) -> SensorModel:
        """The measurement chain :attr:`sensors` names."""
        return SensorModel.ideal() if self.sensors == "ideal" else SensorModel()

    def chain(self) -> dict[str, Any]:
        """The measurement chain's choices where they differ from the default (for keys)."""
        if (self.sensors, self.drift) == ("default", True):
            return {}
        return {"sensors": self.sensors, "drift": self.drift}

    def key(self) -> str:
        """The campaign's key: artic's code, the seed, models, gain, part, truth and chain.

        A registered model's own code fingerprint joins it. The campaign's
        saved stage times (``timings.json``) and efficiency belong to this key.
        """
        from artic.validation.models import code_of
        from artic.validation.plumbing import fingerprint

        c = self.resolved()
        outside = {m: code for m in c.models or () if (code := code_of(m))}
        chain = c.chain()
        tuning = {"tuning": c.tuning} if c.tuning != "default" else {}
        return fingerprint.key(c.seed, list(c.models or ()), c.gain,
                               list(c.only) if c.only else None, c.truth,
                               *([outside] if outside else []), *([chain] if chain else []),
                               *([tuning] if tuning else []))

    def tuning_logs(self) -> tuple[str, ...]:
        """The names of the manoeuvres :attr:`tuning` fits on."""
        return tuning_set(self.tuning)

    def options(self) -> dict[str, Any]:
        """The choices as a dict of plain values (the pooled report names them)."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)
                if f.name not in ("out_dir", "dask")}


def check_selection(only: tuple[str, ...] | list[str] | None, tuning: str = "default") -> None:
    """Refuse an ``--only`` that leaves nothing to validate, before any work.

    The tuning manoeuvres (``tuning``'s set of
    :data:`~artic.validation.synthetic.testmatrix.TUNING_SETS`) are fitted on and
    never validated; a selection of them alone would tune and then have no log
    for the tables.

    Raises
    ------
    UserError
        One line naming the selection and what to add.
    """
    if not only:
        return
    check_only(only)
    names = tuning_set(tuning)
    chosen = [m.name for m in selected(only)]
    if chosen and all(n in names for n in chosen):
        first = next(m.name for m in MATRIX if m.name not in names)
        raise UserError(f"--only {','.join(only)}: selects only tuning manoeuvres "
                        f"({', '.join(chosen)}), which are fitted on and never validated, "
                        "so there would be nothing to validate; add a validation manoeuvre "
                        f"(for example --only {','.join(only)},{first})")
