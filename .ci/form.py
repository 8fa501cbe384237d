"""Policies about the layout's form, checked in CI as a lint step, not as tests.

``validation/`` is the map a newcomer reads (``docs/contributing.md``): a module
is found by the room of its job. These rules keep the map readable; they say
nothing about what artic computes, so they live here instead of in the test
suite::

    python .ci/form.py            # one line per breach; exit status 1 if any

- validation's root holds only the model registry and the pytest plugin
  (:data:`ROOT_MODULES`); a new module goes into the room of its job;
- each room's ``__init__`` docstring says the room's job in a first line of
  its own (a sentence of three words or more), and names only modules that
  exist (a renamed or moved module leaves no stale pointer).
"""

from __future__ import annotations

import ast
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

ROOT_MODULES = frozenset({"__init__.py", "models.py", "testing.py"})
"""What validation's root holds: the model registry every room reads, and the pytest
plugin (its import path, ``artic.validation.testing``, is what users write)."""

ROOMS = ("plumbing/, logs/, harness/, criteria/, synthetic/, runs/, review/, campaign/, docking/, "
         "cli/")


def job(doc: str | None) -> str:
    """The job a room's docstring states: its first line, if it is a sentence of its own."""
    first = (doc or "").strip().splitlines()[0] if (doc or "").strip() else ""
    return first if len(first.split()) >= 3 and first.endswith(".") else ""


def named_modules(doc: str) -> set[str]:
    """The artic modules a docstring refers to by role, e.g. :mod:`~artic.validation.x`."""
    return set(re.findall(r":mod:`~?(artic\.[\w.]+)`", doc))


def exists(module: str, root: Path = ROOT) -> bool:
    """Whether ``artic.a.b`` is a module or package of the tree at ``root``.

    The four rooms sit at the root (``artic.validation`` is ``validation/``); the
    front door's own modules in ``artic/`` (``artic.gym`` is ``artic/gym.py``).
    """
    rel = Path(*module.split(".")[1:])
    return any((base / rel).with_suffix(".py").is_file() or (base / rel / "__init__.py").is_file()
               for base in (root, root / "artic"))


def problems(root: Path = ROOT) -> list[str]:
    """Every breach of the rules in the tree at ``root``, one line each naming the fix."""
    validation = root / "validation"
    out = []
    extra = sorted({p.name for p in validation.glob("*.py")} - ROOT_MODULES)
    if extra:
        out.append(f"validation/ holds {', '.join(extra)} beside {', '.join(sorted(ROOT_MODULES))}"
                   f": put a new module in the room of its job ({ROOMS})")
    for init in sorted(validation.rglob("__init__.py")):
        if "__pycache__" in init.parts:
            continue
        where = init.relative_to(root).as_posix()
        doc = ast.get_docstring(ast.parse(init.read_text(encoding="utf-8")))
        if not job(doc):
            out.append(f"{where}: its docstring's first line must say the room's job")
        stale = sorted(m for m in named_modules(doc or "") if not exists(m, root))
        if stale:
            out.append(f"{where}: its docstring names {', '.join(stale)}, which do not exist")
    return out


def main() -> int:
    """Print every breach; 1 if any."""
    found = problems()
    for line in found:
        print(f".ci/form.py: {line}", file=sys.stderr)
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
