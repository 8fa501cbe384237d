"""The campaign lets go of what no later stage reads (its peak memory, issue 42)."""

from __future__ import annotations

import weakref

import pandas as pd

from artic.validation.campaign import main
from artic.validation.campaign.cache import StageResult
from artic.validation.logs.runfile import Run


def _campaign() -> main._Campaign:
    # what _without_twin_logs reads of a campaign: its results by stage
    return main._Campaign(config=None, pool=None, cache=None, timer=None)


def test_the_twin_logs_are_freed_after_the_twins_and_the_logs_kept():
    c = _campaign()
    logs = [Run(pd.DataFrame({"t": [0.0, 0.01]}), {"name": "a"})]
    twins = [Run(pd.DataFrame({"t": [0.0, 0.01]}), {"name": "a"})]
    frame = weakref.ref(twins[0].frame)
    c.results["logs"] = result = StageResult("logs", "k", False, {"x": "y"}, (logs, twins))
    del twins
    kept = main._without_twin_logs(c, result)
    del result  # no collection: the frames must go when their last reference does
    # the stage's key and outputs (what later stages' keys and the report read) unchanged
    assert (kept.name, kept.key, kept.reused, kept.outputs) == ("logs", "k", False, {"x": "y"})
    assert kept.value[0] is logs and kept.value[1] is None
    assert c.results["logs"] is kept
    assert frame() is None  # nothing else held the twins' frames: their memory is back


def test_a_campaign_without_twins_keeps_its_logs_result():
    c = _campaign()
    result = StageResult("logs", "k", True, {}, ([], None))
    c.results["logs"] = result
    assert main._without_twin_logs(c, result) is result
