"""The campaign's tables per manoeuvre class, its oracle rows, and the choice of tuning logs."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from artic.mjcf.errors import UserError
from artic.validation.campaign.config import CampaignConfig
from artic.validation.synthetic.testmatrix import MATRIX, TUNING, TUNING_SETS, tuning_set


def test_the_tuning_choices_and_the_default_unchanged(tmp_path):
    assert tuning_set("default") == TUNING
    kinds = {c: {m.kind for m in MATRIX if m.name in names} for c, names in TUNING_SETS.items()}
    assert kinds == {"default": {"constant-steer", "slalom"}, "slaloms": {"slalom"},
                     "transient": {"slalom", "figure-8"}}
    # Every choice tunes forward, on both load conditions.
    for names in TUNING_SETS.values():
        chosen = [m for m in MATRIX if m.name in names]
        assert {m.direction for m in chosen} == {"forward"}
        assert {m.load for m in chosen} == {"unloaded", "loaded"}
    assert CampaignConfig(tmp_path).tuning_logs() == TUNING
    assert CampaignConfig(tmp_path, tuning="slaloms").key() != CampaignConfig(tmp_path).key()
    with pytest.raises(UserError, match="--tuning bogus: choose from default, slaloms"):
        CampaignConfig(tmp_path, tuning="bogus")
    # A selection of one choice's tuning logs alone is refused, naming the choice's logs.
    with pytest.raises(UserError, match="selects only tuning manoeuvres"):
        CampaignConfig(tmp_path, tuning="slaloms", only=("58-", "59-"))
    CampaignConfig(tmp_path, only=("58-", "02-"))  # a validated log beside them: accepted


@pytest.mark.slow
def test_a_part_campaign_writes_class_tables_and_oracle_rows(tmp_path):
    from artic.validation.campaign.main import run_campaign

    out = tmp_path / "out"
    only = ["58-", "59-", "02-constant-steer", "04-constant-steer", "27-ramp", "28-ramp"]
    paths = run_campaign(out, models=("kin", "stm"), only=only, jobs=2, recordings=False,
                         sweep_models=(), closing=False, tuning="slaloms")
    fitted = json.loads((out / "tuning.json").read_text())["loads"]
    assert fitted["unloaded"]["logs"] == ["58-slalom-unloaded-360deg-8kph-left",
                                          "59-slalom-unloaded-360deg-8kph-right"]
    metrics = pd.read_csv(paths["metrics"])
    by_class = pd.read_csv(paths["table2_forward_by_class"], index_col="model")
    # Tuned on slaloms: the validated constant steers are no tuning class.
    assert set(by_class["class"]) == {"constant-steer"}
    reverse = pd.read_csv(paths["table3_reverse_by_class"], index_col="model")
    assert set(reverse["class"]) == {"ramp-steer-reverse"}
    # Each class row is the mean of that class's rows of metrics.csv (6 digits in CSV).
    rows = metrics[(metrics["manoeuvre"] == "ramp-steer-reverse") & (metrics["model"] == "kin")]
    assert reverse.loc["kin", "steer_fb"] == pytest.approx(rows["steer_fb"].mean(), rel=1e-5)
    assert reverse.loc["kin", "n"] == len(rows) == 2
    # The absolute counterpart beside J_steer, in degrees, finite and positive in reverse.
    assert (rows["steer_fb"] > 0).all()
    oracle = pd.read_csv(paths["metrics_oracle"])
    assert set(oracle["model"]) == {"kin-oracle", "stm-oracle"}
    assert set(oracle["log"]) == set(metrics["log"])  # every validated log, and no other
    split = pd.read_csv(paths["form_reverse"], index_col="model")
    assert {"kin form", "kin parameters", "stm form", "stm parameters"} <= set(split.index)
    text = paths["report"].read_text()
    for section in ("## Per manoeuvre class", "## Model form and parameters"):
        assert section in text
    assert "tuning classes: slalom" in text
    assert (out / "params" / "oracle-unloaded.toml").is_file()
    share = (out / "noise_share_reverse_by_class.md").read_text()
    assert "## ramp-steer-reverse" in share and "steer_fb [deg]" in share
