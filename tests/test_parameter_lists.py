"""No function of artic takes more than ten parameters: a group that travels together is an object.

Read from the source (no import), so it covers every module, compiled kernels
included. ``validation/docking`` has its own test of the same rule. ``self`` and
``cls`` do not count; ``*args`` and ``**kwargs`` count one each.
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ROOMS = ("artic", "mjcf", "plant", "reduced", "validation")
MAX_PARAMETERS = 10


def parameter_count(fn: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    """Parameters of ``fn`` as a caller gives them: ``self``/``cls`` left out, ``*``/``**`` one."""
    a = fn.args
    names = [p.arg for p in a.posonlyargs + a.args]
    count = len(names) + len(a.kwonlyargs) + (a.vararg is not None) + (a.kwarg is not None)
    return count - (bool(names) and names[0] in ("self", "cls"))


def long_lists(root: Path = ROOT) -> dict[tuple[str, str], int]:
    """Every function of artic outside ``validation/docking`` with too many parameters."""
    out = {}
    for room in ROOMS:
        for path in sorted((root / room).rglob("*.py")):
            rel = path.relative_to(root).as_posix()
            if rel.startswith("validation/docking/"):
                continue
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    n = parameter_count(node)
                    if n > MAX_PARAMETERS:
                        out[(rel, node.name)] = n
    return out


def test_no_function_takes_more_than_ten_parameters():
    found = long_lists()
    assert not found, f"more than {MAX_PARAMETERS} parameters (group them in an object): {found}"


def test_the_count_sees_a_long_list(tmp_path):
    # The walk finds a function with eleven parameters, and leaves self out of a method's.
    (tmp_path / "plant").mkdir()
    (tmp_path / "plant" / "m.py").write_text(
        "def f(a, b, c, d, e, f, g, h, i, j, *, k): pass\n"
        "class C:\n    def g(self, a, b, c, d, e, f, g, h, i, j): pass\n")
    assert long_lists(tmp_path) == {("plant/m.py", "f"): 11}
