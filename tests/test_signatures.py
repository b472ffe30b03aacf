"""Kernels pass records, not long positional argument lists (issue 44): no function in
``engine/`` takes more than :data:`MOST` parameters unless its docstring says why."""
from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
#: Most parameters a function of the engine takes (``self``/``cls`` not counted).
MOST = 12
#: What a docstring says to explain more (a measured cost, or why a record would not help).
WHY = "Why so many parameters"


def parameter_count(node: ast.FunctionDef) -> int:
    """Parameters of ``node``: positional, keyword-only, ``*args`` and ``**kw``, less ``self``."""
    a = node.args
    n = len(a.posonlyargs) + len(a.args) + len(a.kwonlyargs) + (a.vararg is not None) + (a.kwarg is not None)
    first = (a.posonlyargs + a.args)[:1]
    return n - (1 if first and first[0].arg in ("self", "cls") else 0)


def long_signatures(source: str, path: str = "<source>") -> list[str]:
    """``path:line name (count)`` of every function in ``source`` over :data:`MOST` parameters
    whose docstring does not say why."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and parameter_count(node) > MOST:
            if WHY not in (ast.get_docstring(node) or ""):
                found.append(f"{path}:{node.lineno} {node.name} ({parameter_count(node)})")
    return found


def test_no_engine_function_takes_more_than_twelve_parameters():
    found = [hit for p in sorted((ROOT / "engine").rglob("*.py"))
             for hit in long_signatures(p.read_text(encoding="utf-8"), str(p.relative_to(ROOT)))]
    assert found == [], "pass a record (engine/tracer/kernels/records.py) or say why:\n" + "\n".join(found)


def test_the_check_sees_a_long_signature_and_accepts_one_explained():
    args = ", ".join(f"a{i}" for i in range(MOST + 1))
    assert long_signatures(f"def f({args}):\n    pass\n") == ["<source>:1 f (13)"]
    assert long_signatures(f"def f(self, {', '.join(f'a{i}' for i in range(MOST))}):\n    pass\n") == []
    assert long_signatures(f'def f({args}):\n    """{WHY}: measured."""\n') == []
