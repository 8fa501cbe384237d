"""Shared fixtures: presets, and logs made by the models themselves."""

from __future__ import annotations

import pytest

from artic.validation.runs import runtime

# As the artic command does: numba's cache folder before any compiled model is imported.
runtime.configure()

from artic.mjcf import load_vehicle  # noqa: E402


def pytest_configure(config):
    # artic's pytest plugin (artic_logs, ...) comes from its pytest11 entry
    # point; an environment installed before the plugin existed, or with
    # PYTEST_DISABLE_PLUGIN_AUTOLOAD set, gets it here.
    if not config.pluginmanager.has_plugin("artic"):
        from artic.validation import testing

        config.pluginmanager.register(testing, "artic")


@pytest.fixture(scope="session")
def unloaded():
    return load_vehicle("gosar2022-unloaded")


@pytest.fixture(scope="session")
def loaded():
    return load_vehicle("gosar2022-loaded")
