"""The layers of the code: packages import only the layers below them (so no two packages import
each other, lazily or not), and so do the sub-layers of a package that has them (the tracer's
kernels, tables and the rest), no import circles between modules, widgets never import the
application shell, and the geometry and camera maths the panels use live in the engine."""
from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("app", "widgets", "engine")


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _imports(path: Path, known: set[str]) -> set[str]:
    """Modules of this repository that ``path`` imports, at any depth of its code."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    here = _module_name(path).split(".")
    package = here if path.name == "__init__.py" else here[:-1]
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = ".".join(package[:len(package) - node.level + 1] + ([base] if base else []))
            names = [base] + [f"{base}.{a.name}" for a in node.names]
        else:
            continue
        found |= {n for n in names if n in known}
    return found


def _graph() -> dict[str, set[str]]:
    files = [p for pkg in PACKAGES for p in (ROOT / pkg).rglob("*.py")]
    known = {_module_name(p) for p in files}
    return {_module_name(p): _imports(p, known) - {_module_name(p)} for p in files}


def _cycle(graph: dict[str, set[str]]) -> list[str] | None:
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if nxt.rsplit(".", 1)[0] == node or node.rsplit(".", 1)[0] == nxt:
                continue  # a package and its own modules (re-exports) are one unit
            if state.get(nxt) == 1:
                return stack[stack.index(nxt):] + [nxt]
            if nxt not in state:
                found = visit(nxt)
                if found:
                    return found
        stack.pop()
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state:
            found = visit(node)
            if found:
                return found
    return None


def test_no_module_imports_itself_through_others():
    assert _cycle(_graph()) is None, f"import circle: {' -> '.join(_cycle(_graph()))}"


#: The packages from the bottom up (docs/ARCHITECTURE.md draws them): a package may import its
#: own modules and the packages of the layers below its own, never one of its own layer or above.
LAYERS = (
    ("engine.errors",),
    ("engine.limits", "engine.color", "engine.io"),
    ("engine.geometry",),
    ("engine.intersect", "engine.model"),
    ("engine.appearance",),
    ("engine.operations", "engine.plant"),
    ("engine.files", "engine.tracer"),
    ("engine.finals",),
    ("engine.batch", "engine.export"),
    ("engine.cli",),
    ("widgets",),
    ("app",),
)


#: Packages whose own folders are layered too, from the bottom up; the last is the package itself
#: (its modules outside those folders). The tracer: the compiled kernels, the row builders that
#: fill their tables, then what runs a render (docs/ARCHITECTURE.md). A module may import its own
#: sub-layer and those below it, so a folder and the rest of its package never import each other.
SUBLAYERS = {
    "engine.tracer": ("engine.tracer.kernels", "engine.tracer.tables", "engine.tracer"),
}


def _package(module: str) -> str | None:
    """The layered package a module belongs to (``engine`` itself, the root, is none)."""
    for layer in LAYERS:
        for pkg in layer:
            if module == pkg or module.startswith(pkg + "."):
                return pkg
    return None


def _level(pkg: str) -> int:
    return next(i for i, layer in enumerate(LAYERS) if pkg in layer)


def _sublevel(module: str, pkg: str) -> int:
    """Where ``module`` of ``pkg`` stands among its :data:`SUBLAYERS` (the deepest that holds it)."""
    subs = SUBLAYERS[pkg]
    return subs.index(max((s for s in subs if module == s or module.startswith(s + ".")), key=len))


def _wrong_way(graph: dict[str, set[str]]) -> list[str]:
    """Every import from a package to one of its own layer or above, and within a package with
    sub-layers from one sub-layer to another above it, as ``module -> module``."""
    out = []
    for mod, deps in graph.items():
        a = _package(mod)
        for dep in deps:
            b = _package(dep)
            if a and b and a != b and _level(b) >= _level(a):
                out.append(f"{mod} -> {dep}")
            elif a and a == b and a in SUBLAYERS and _sublevel(dep, a) > _sublevel(mod, a):
                out.append(f"{mod} -> {dep}")
    return sorted(out)


def test_packages_import_only_the_layers_below_them():
    graph = _graph()
    assert {_package(m) for m in graph if m != "engine"} == {p for layer in LAYERS for p in layer}, \
        "a package is missing from LAYERS (or LAYERS names one that is gone)"
    assert all(any(m == s or m.startswith(s + ".") for m in graph) for subs in SUBLAYERS.values() for s in subs), \
        "SUBLAYERS names a folder that is gone"
    assert _wrong_way(graph) == []


def test_the_layer_check_refuses_an_import_upwards_and_sideways():
    graph = {"engine.model.design": {"engine.appearance.frame"}, "engine.files.project": {"engine.tracer.job"},
             "engine.tracer.job": {"engine.model.design"}}
    assert _wrong_way(graph) == ["engine.files.project -> engine.tracer.job",
                                 "engine.model.design -> engine.appearance.frame"]


def test_the_layer_check_sees_a_pair_planted_in_the_tracer():
    """Issue 44's last two-way folder pair planted back into a copy of the real graph: a row
    builder importing up into the tracer that imports it, and a kernel importing a row builder."""
    graph = {mod: set(deps) for mod, deps in _graph().items()}
    assert "engine.tracer.tables.render_objects" in graph["engine.tracer.context"]
    assert "engine.tracer.kernels.ground" in graph["engine.tracer.tables.stage"]
    graph["engine.tracer.tables.render_objects"].add("engine.tracer.context")
    graph["engine.tracer.kernels.ground"].add("engine.tracer.tables.stage")
    assert _wrong_way(graph) == ["engine.tracer.kernels.ground -> engine.tracer.tables.stage",
                                 "engine.tracer.tables.render_objects -> engine.tracer.context"]


def test_the_cycle_finder_finds_a_circle():
    assert _cycle({"a.x": {"a.y"}, "a.y": {"a.z"}, "a.z": {"a.x"}}) == ["a.x", "a.y", "a.z", "a.x"]


def test_widgets_never_import_the_application_shell():
    graph = _graph()
    bad = {m: sorted(d for d in deps if d.startswith("app")) for m, deps in graph.items()
           if m.startswith("widgets")}
    assert not {m: d for m, d in bad.items() if d}
def test_section_geometry_and_orbit_maths_live_in_the_engine():
    import engine.geometry.editing as editing
    import engine.model.orbit as orbit
    for name in ("move_joint", "convert_segment", "split_segment", "set_arc_radius", "handles_of"):
        assert callable(getattr(editing, name))
    assert callable(orbit.camera_to_orbit) and callable(orbit.orbit_to_camera)
    assert not (ROOT / "widgets" / "section_edits.py").exists()
