"""Reference data from ``../shared`` beside the clone, and how tests skip without it.

CI clones artic with ``shared/`` beside it, and every test here runs there. A
user's clone has no ``../shared``: the tests that compare against its data
skip, and the skip reason names the missing file.
"""

from __future__ import annotations

from pathlib import Path

import pytest

SHARED = Path(__file__).resolve().parents[2] / "shared"

REFERENCE_TYRE = SHARED / "data" / "tyres" / "315_80R22.5_PAC2002.tir"
"""A real 315/80R22.5 truck tyre in PAC2002 format (not shipped with artic)."""


def needs(path: Path) -> pytest.MarkDecorator:
    """Skip, naming ``path``, when the reference file is not beside the clone."""
    return pytest.mark.skipif(
        not path.is_file(),
        reason=f"reference data {path} is absent: it is in ../shared beside a CI clone, "
               "not in artic itself")
