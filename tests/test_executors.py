"""The campaign's runs on a Dask cluster give what they give locally."""

from __future__ import annotations

import pytest

from artic.validation.campaign.executors import cluster_executor
from artic.validation.plumbing.budget import BUDGET
from artic.validation.runs.validate import validate_runs
from artic.validation.synthetic.generate import generate_campaign
from tests.helpers import straight_log


def test_executor_choices_are_checked():
    with pytest.raises(ValueError, match="executor 'spark'"):
        with cluster_executor("spark"):
            pass
    with pytest.raises(ValueError, match="--scheduler needs --executor dask"):
        with cluster_executor("local", address="tcp://x:1"):
            pass
    with cluster_executor("local") as ex:
        assert ex is None


@pytest.mark.slow
def test_dask_local_cluster_equals_local_runs(tmp_path, unloaded):
    logs = [straight_log(n=800, u=-0.8, gamma0=0.05),
            straight_log(n=500, u=1.2, delta_h=1.0)]
    logs[1].meta["name"] = "forward"
    name = ["28-ramp-steer-reverse-unloaded-30deg-6kph-right"]
    before = BUDGET.snapshot()
    local = validate_runs(logs, unloaded, ["kin", "mbd"])
    counted = BUDGET.since(before)
    before = BUDGET.snapshot()
    generate_campaign(tmp_path / "local", only=name)
    assert BUDGET.since(before)["multibody"][0] == 1  # the generator counts its drive
    with cluster_executor("dask", jobs=2) as ex:
        before = BUDGET.snapshot()
        remote = validate_runs(logs, unloaded, ["kin", "mbd"], executor=ex,
                               out_dir=tmp_path / "val")
        # What the workers simulated is counted here, as the local runs were.
        for kind, (runs, seconds) in BUDGET.since(before).items():
            assert runs == counted[kind][0] and seconds == pytest.approx(counted[kind][1])
        before = BUDGET.snapshot()
        generate_campaign(tmp_path / "dask", only=name, executor=ex)
        assert BUDGET.since(before)["multibody"][0] == 1  # counted here, driven there
    assert counted["multibody"][0] >= 2 and counted["reduced"][0] >= 2
    cols = [c for c in local.columns if c != "wall_s"]
    assert local[cols].equals(remote[cols])
    assert len(list((tmp_path / "val" / "runs").glob("*.parquet"))) == 4
    a, b = (sorted((tmp_path / d / name[0]).iterdir()) for d in ("local", "dask"))
    assert [p.name for p in a] == [p.name for p in b]
    assert all(p.read_bytes() == q.read_bytes() for p, q in zip(a, b, strict=True))


def test_threads_equal_serial(unloaded):
    logs = [straight_log(n=600, u=-0.8, gamma0=0.05), straight_log(n=400, u=1.2, delta_h=1.0)]
    logs[1].meta["name"] = "forward"
    serial = validate_runs(logs, unloaded, ["kin", "stm", "mbd"], jobs=1)
    threads = validate_runs(logs, unloaded, ["kin", "stm", "mbd"], jobs=2)
    cols = [c for c in serial.columns if c != "wall_s"]
    assert serial[cols].equals(threads[cols])
