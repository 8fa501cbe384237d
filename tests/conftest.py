"""Shared fixtures: presets, logs made by the models themselves, and the campaigns.

A campaign is the costliest thing a test can make, so each kind is made once per
session and shared by every test that reads its output: ``default_campaign`` (the
README's first command, for the slow end-to-end checks) and ``small_campaign``
(every cached stage on two manoeuvres, for the fast set). Across processes
(pytest-xdist) each test file runs whole in one, the default campaign's file
first. No test writes into them; a test that changes a campaign works in a
copy (``shutil.copytree`` keeps the files' times, so the stage cache stays
valid there).
"""

from __future__ import annotations

import gc
import os
import subprocess
import sys
from pathlib import Path

import pytest

from artic.validation.plumbing import runtime

# As the artic command does: numba's cache folder before any compiled model is imported.
runtime.configure()
# The fixtures import what they make (the campaign, the presets) when first asked: a
# pytest process that runs none of them (the suite's own checks start several) does
# not pay 1.8 s importing the campaign.


def _untraced_fork() -> None:
    """In a forked child: stop the coverage tracer it inherited, and never save its data.

    pytest-cov traces this process; a child forked from it (the campaign's and the
    sweeps' worker pools, the docking supervisor) inherits the tracer, which slows
    its Python about 2.4 times, but its data is never written: multiprocessing ends
    its children with ``os._exit``, before coverage's exit hook. So the trace in a
    child only costs time; what the children run is measured where a test runs it
    in this process.
    """
    try:
        import coverage
    except ImportError:
        return
    cov = coverage.Coverage.current()
    if cov is not None:
        cov._auto_save = False  # as coverage's own fork hook does: not the parent's data
        cov.stop()


os.register_at_fork(after_in_child=_untraced_fork)


def pytest_configure(config):
    # artic's pytest plugin (artic_logs, ...) comes from its pytest11 entry
    # point; an environment installed before the plugin existed, or with
    # PYTEST_DISABLE_PLUGIN_AUTOLOAD set, gets it here.
    if not config.pluginmanager.has_plugin("artic"):
        from artic.validation import testing

        config.pluginmanager.register(testing, "artic")
    if getattr(config.option, "dist", "no") == "loadfile":
        # Deal the files in the order the collection hook below sorts them
        # (pytest-xdist's default deals the files with the most tests first).
        config.option.loadscopereorder = False


def _distributed(config) -> bool:
    """Whether pytest-xdist deals this run's files to processes: its controller or a worker."""
    return hasattr(config, "workerinput") or getattr(config.option, "dist", "no") == "loadfile"


def pytest_collection_modifyitems(config, items):
    # Across processes (the README's ``-n auto --dist loadfile``) each test file
    # runs whole in one process, so its module fixtures are made once. The
    # files are dealt in this order: first the one that reads the default
    # campaign (the costliest fixture, minutes; tests/test_default_campaign.py),
    # then the files with slow tests, then the rest, so that the long work
    # starts early and the processes end together. Without xdist, nothing changes.
    if not _distributed(config):
        return
    campaign = {item.path for item in items if "default_campaign" in item.fixturenames}
    slow = {item.path for item in items if item.get_closest_marker("slow")}
    items.sort(key=lambda item: (item.path not in campaign, item.path not in slow))


@pytest.fixture(scope="module", autouse=True)
def _settled_heap():
    """Each test file starts with what earlier files left alive frozen out of the collector.

    A full collection walks every object the process holds; one process runs many
    files (pytest-xdist), and the campaign collects after each stage (its
    ``release_memory``), as statsmodels' ``multipletests`` does on every call: in a
    process that had run half the suite each took half a second. What is alive when
    a file starts (imported modules, session fixtures, caches) lives on, so it is
    collected once here and frozen (:func:`gc.freeze`); the file's own objects are
    collected as before.
    """
    gc.collect()
    gc.freeze()
    yield


@pytest.fixture(scope="session")
def unloaded():
    from artic.mjcf import load_vehicle

    return load_vehicle("gosar2022-unloaded")


@pytest.fixture(scope="session")
def loaded():
    from artic.mjcf import load_vehicle

    return load_vehicle("gosar2022-loaded")


@pytest.fixture(scope="session")
def small_campaign(tmp_path_factory) -> Path:
    """The output folder of :data:`SMALL_CAMPAIGN`, made once per session; read only."""
    from artic.validation.campaign.config import CampaignConfig
    from artic.validation.campaign.main import run_campaign
    from tests.helpers import SMALL_CAMPAIGN

    out = tmp_path_factory.mktemp("small-campaign") / "out"
    run_campaign(CampaignConfig(out, **SMALL_CAMPAIGN))
    return out


@pytest.fixture(scope="session")
def default_campaign(tmp_path_factory) -> Path:
    """The README's first command's campaign (all 63 manoeuvres, recordings), once per
    session, for the slow tests that check it whole; read only.

    It runs as the README runs it: the ``artic campaign --out-dir DIR`` command, in
    a process of its own on every core (its default ``--jobs``). That process is not
    under the coverage tracer, which slowed the campaign's own Python (its tables,
    its criteria, the threads beside the compiled loops) for lines that the part
    campaigns of ``tests/test_campaign.py`` cover in this process.
    ``tests/test_default_campaign.py`` alone under ``--cov``, median (range) of three
    runs each, alternately: 151 s (148-151) of wall and 253 s (248-253) of CPU in this
    process, 133 s (131-140) and 229 s (227-239) as a command (quiet, two cores,
    2026-12-07).
    """
    out = tmp_path_factory.mktemp("default-campaign") / "out"
    # What the installed ``artic`` script runs, wherever the installer put the script.
    command = [sys.executable, "-c", "import sys; from artic.validation.cli.entry import main; "
               "sys.argv[0] = 'artic'; sys.exit(main())", "campaign", "--out-dir", str(out)]
    # An hour: the campaign takes about two minutes alone and four beside the other tests.
    done = subprocess.run(command, capture_output=True, text=True, timeout=3600)
    assert done.returncode == 0, done.stderr[-3000:]
    return out
