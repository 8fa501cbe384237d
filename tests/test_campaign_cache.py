"""The campaign's configuration object and its one stage cache.

The session's small campaign (``small_campaign`` in ``tests/conftest.py``: KIN
alone on a forward tuning slalom and a reverse ramp steer, the gain sweep of
KIN, no recordings) is made once; each test runs again in a copy of it (copied
with the files' times, so its cache entries stay valid there).
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pandas as pd
import pytest

from artic.mjcf.errors import UserError
from artic.validation.campaign.cache import StageCache, StageResult
from artic.validation.campaign.config import CampaignConfig
from artic.validation.campaign.main import run_campaign
from artic.validation.logs.importers import import_source
from tests.helpers import SMALL_CAMPAIGN as SMALL

CACHED = ("logs", "tuning", "validation", "references", "twins", "oracle", "efficiency",
          "gain sweep", "pbs")


@pytest.fixture
def made(small_campaign) -> Path:
    return small_campaign


def again(made: Path, where: Path, capsys, **changes) -> tuple[dict[str, bool], str]:
    """Run the small campaign again in a copy of ``made``; which stages were reused, stderr."""
    shutil.copytree(made, where)  # copy2: sizes and modification times kept
    capsys.readouterr()
    run_campaign(CampaignConfig(where, **{**SMALL, **changes}))
    reused = json.loads((where / "timings.json").read_text())["reused"]
    return reused, capsys.readouterr().err


# A partial campaign end to end: in the slow set (issue 42, the fast suite's budget).
@pytest.mark.slow
def test_a_second_run_reuses_every_stage_and_writes_the_same_numbers(made, tmp_path, capsys):
    first = json.loads((made / "timings.json").read_text())["reused"]
    assert not any(first.values())  # the first run computed every stage
    reused, err = again(made, tmp_path / "out", capsys)
    assert set(CACHED) <= set(reused) and all(reused.values()), reused
    assert "stages reused: logs, tuning, validation, references, twins" in err
    assert "computed: none" in err
    for f in ("metrics.csv", "table3_reverse.csv", "gain_sweep.csv", "efficiency.csv"):
        assert (tmp_path / "out" / f).read_bytes() == (made / f).read_bytes(), f


# A partial campaign end to end: in the slow set (issue 42, the fast suite's budget).
@pytest.mark.slow
def test_a_changed_gain_reruns_validation_and_what_depends_on_it(made, tmp_path, capsys):
    reused, _ = again(made, tmp_path / "out", capsys, gain=2.0)
    # K enters the harness, not the logs nor the tuning (open loop, forward).
    assert reused["logs"] and reused["tuning"]
    assert not any(reused[s] for s in ("validation", "references", "twins", "oracle",
                                       "gain sweep", "efficiency", "tables", "report"))
    before = pd.read_csv(made / "metrics.csv").set_index(["log", "model"])
    after = pd.read_csv(tmp_path / "out" / "metrics.csv").set_index(["log", "model"])
    reverse = before.direction == "reverse"
    # Another K steers the reverse runs otherwise: their criteria change.
    assert (before.loc[reverse, "J_steer"] != after.loc[reverse, "J_steer"]).all()


# A partial campaign end to end: in the slow set (issue 42, the fast suite's budget).
@pytest.mark.slow
def test_a_corrupted_entry_or_output_is_computed_again(made, tmp_path, capsys):
    out = tmp_path / "out"
    shutil.copytree(made, out)
    (out / "cache" / "tuning.json").write_text('{"key": "cut sh')  # a crash mid-write
    export = next((out / "synthetic").glob("28-*"))
    expected = import_source(export)[0].frame
    table = export / "tractor.csv.gz"
    table.write_bytes(table.read_bytes()[:100])  # an output cut short
    capsys.readouterr()
    run_campaign(CampaignConfig(out, **SMALL))
    reused = json.loads((out / "timings.json").read_text())["reused"]
    err = capsys.readouterr().err
    assert "tuning.json: unreadable (JSONDecodeError)" in err
    assert f"synthetic/{export.name}/tractor.csv.gz changed since it was made" in err
    assert f"{export}: does not import" in err  # and so it is generated again
    assert not reused["logs"] and not reused["tuning"]
    assert import_source(export)[0].frame.equals(expected)  # the same seed, the same log
    # The stages after them read the same inputs under the same keys: reused.
    assert reused["validation"] and reused["references"]
    assert (out / "metrics.csv").read_bytes() == (made / "metrics.csv").read_bytes()


def test_an_entry_is_trusted_only_with_its_key_and_intact_outputs(tmp_path):
    cache = StageCache(tmp_path)
    f = tmp_path / "a.csv"
    f.write_text("x\n1\n")
    key = cache.key("tables", {"gain": 3.0})
    # The key is the stage's inputs: another field value or upstream key changes it.
    assert key != cache.key("tables", {"gain": 2.0}) != cache.key("validation", {"gain": 3.0})
    assert cache.key("tables", {"gain": 3.0}, [StageResult("logs", "k1", True)]) != \
        cache.key("tables", {"gain": 3.0}, ["k2"])
    cache.store("tables", key, {"a": f}, {"rows": [1.5, float("nan")]})
    entry = cache.lookup("tables", key)
    assert entry.outputs == {"a": f} and entry.data["rows"][0] == 1.5
    assert cache.lookup("tables", "another key") is None
    f.unlink()
    assert cache.lookup("tables", key) is None  # its output is gone
    assert cache.lookup("validation", key) is None  # no entry at all
    cache.forget("tables")
    assert not cache.path("tables").exists()


def test_the_config_checks_its_options_and_keys_them_alike(tmp_path):
    c = CampaignConfig(tmp_path, models=["kin"], only=["00-", "28-"])
    assert c.only == ("00-", "28-") and c.models == ("kin",)
    assert c.key() == CampaignConfig(tmp_path / "elsewhere", models=("kin",),
                                     only=("00-", "28-"), jobs=1).key()  # not where, nor how
    assert c.key() != CampaignConfig(tmp_path, models=("kin",), only=("00-", "28-"),
                                     gain=2.0).key()
    one = CampaignConfig(tmp_path, seeds=3, seed=4).for_seed(5, tmp_path / "seed-5")
    assert (one.seed, one.seeds, one.closing, one.out_dir) == (5, 1, False, tmp_path / "seed-5")
    for bad, match in (({"seeds": 0}, "--seeds 0"), ({"sensors": "noisy"}, "--sensors noisy"),
                       ({"only": ["00-"]}, "--only 00-: selects only tuning")):
        with pytest.raises(UserError, match=match):
            CampaignConfig(tmp_path, **bad)


def test_a_campaign_without_any_log_to_tune_keeps_the_presets(tmp_path, capsys):
    # No tuning log at all (--only 27-): nothing to fit; it divided by the number of load
    # conditions to tune, zero, before. Both loads keep the presets, and say so.
    from artic.validation.campaign.main import _tune

    tuned = _tune(tmp_path, [], ("kin",), "key", 2)
    assert tuned["complete"] and tuned["loads"] == {}
    err = capsys.readouterr().err
    assert "unloaded: no tuning manoeuvre among the logs" in err
    assert "loaded: no tuning manoeuvre among the logs" in err
