"""The main job on a part of the synthetic campaign."""

from __future__ import annotations

import pandas as pd
import pytest

from validation.campaign import run_campaign


@pytest.mark.slow
def test_campaign_part(tmp_path, capsys):
    only = ["00-constant-steer-unloaded-200deg-5kph-left", "27-ramp-steer-reverse"]
    paths = run_campaign(tmp_path, models=("kin", "stm"), only=only, jobs=2)
    m = pd.read_csv(paths["metrics"])
    assert len(m) == 2 * 2
    assert set(m.direction) == {"forward", "reverse"}
    assert (m.status == "ok").all()
    # The reversing feedback acted on the reverse run only.
    assert (m[m.direction == "reverse"].J_steer > 0).all()
    assert (m[m.direction == "forward"].J_steer == 0).all()
    text = paths["tables"].read_text()
    assert "## Forward" in text and "## Reverse" in text
    # A second run reuses the generated and imported logs.
    run_campaign(tmp_path, models=("kin",), only=only, jobs=1)
    assert "2 of 2 manoeuvres already generated" in capsys.readouterr().err
