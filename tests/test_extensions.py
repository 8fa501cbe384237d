"""The one loader of artic's compiled extensions, and the C they share (mjcf/extensions.*)."""

from __future__ import annotations

import numpy as np
import pytest

from artic.mjcf import extensions
from artic.plant import Plant, PlantWarning, closedloop, ctyre
from artic.validation.synthetic import truthc, yardtruth
from tests.helpers import needs_compiled


def test_a_missing_extension_is_named_with_what_to_do(monkeypatch):
    monkeypatch.delenv(extensions.NO_EXTENSIONS, raising=False)
    lib, why = extensions.load("artic.plant._no_such_extension", "artic", 1, "the thing",
                               "do this")
    assert lib is None
    assert why == "the thing was not built (no C compiler at install time?); do this"
    monkeypatch.setenv(extensions.NO_EXTENSIONS, "1")
    lib, why = extensions.load("artic.plant._tyre_c", "artic", ctyre.ABI, "the callback")
    assert lib is None and f"{extensions.NO_EXTENSIONS} is set" in why


@needs_compiled("the compiled tyre callback")
def test_an_extension_of_another_abi_is_refused():
    lib, why = extensions.load("artic.plant._tyre_c", "artic", ctyre.ABI + 1, "the callback")
    assert lib is None and f"has ABI {ctyre.ABI}, this artic expects {ctyre.ABI + 1}" in why


@needs_compiled("the compiled extensions")
def test_every_extension_loads_through_it_with_the_process_key():
    assert ctyre.library() is not None and not closedloop.unavailable_reason()
    assert truthc.library() is not None and yardtruth._library()[0] is not None
    # The plant's and the truth's seals are one checksum (mjcf/extensions.h).
    body = np.random.default_rng(0).normal(size=300)
    assert ctyre.checksum(body) == float(truthc.library().artic_truth_checksum(
        body.ctypes.data_as(extensions._DOUBLE_P), body.size))
    w = (np.arange(body.size) % 97) + 1.0  # the weights the header documents
    assert np.isclose(ctyre.checksum(body), float(body @ w), rtol=1e-12)


def test_backend_auto_falls_back_to_python_with_a_warning(unloaded, monkeypatch):
    # Without the compiled callback "auto" runs the numpy reference and says
    # why; "compiled" refuses. Faked here, so it runs where the parts are built
    # (in a module that keeps no compiled plant open while it is faked).
    import artic.plant.plant as pp

    monkeypatch.setattr(ctyre, "library", lambda: None)
    monkeypatch.setattr(ctyre, "unavailable_reason", lambda: "no compiler (test)")
    monkeypatch.setattr(pp, "_warned", set())
    with pytest.warns(PlantWarning, match="no compiler"), Plant(unloaded) as p:
        assert p.backend == "python"
    with pytest.raises(RuntimeError, match="no compiler"):
        Plant(unloaded, backend="compiled")
    with pytest.raises(ValueError, match="backend 'fortran'"):
        Plant(unloaded, backend="fortran")
    # The former names of the two backends are refused with their new ones.
    with pytest.raises(ValueError, match="'c' is now 'compiled'"):
        Plant(unloaded, backend="c")
