"""The engine is a plain library: importing every engine module loads no Qt binding."""
from __future__ import annotations

import json
import pkgutil
import subprocess
import sys
from pathlib import Path

import engine

ROOT = Path(__file__).resolve().parent.parent
QT_PREFIXES = ("PySide6", "shiboken6", "pyvistaqt", "PyQt5", "PyQt6")

PROBE = r"""
import importlib, json, pkgutil, sys
import engine
names = sorted(m.name for m in pkgutil.walk_packages(engine.__path__, "engine."))
failed = {}
for name in names:
    try:
        importlib.import_module(name)
    except Exception as exc:  # reported, not hidden: the test asserts on it
        failed[name] = repr(exc)
qt = sorted(m for m in sys.modules if m.split(".")[0] in %r)
print(json.dumps({"modules": names, "failed": failed, "qt": qt}))
""" % (QT_PREFIXES,)


def test_engine_modules_import_without_qt():
    proc = subprocess.run([sys.executable, "-c", PROBE], cwd=ROOT, capture_output=True,
                          text=True, timeout=240)
    assert proc.returncode == 0, proc.stderr
    report = json.loads(proc.stdout.strip().splitlines()[-1])
    expected = {m.name for m in pkgutil.walk_packages(engine.__path__, "engine.")}
    assert set(report["modules"]) == expected
    assert {"engine.model.scene", "engine.files.project", "engine.files.serialize", "engine.cli"} <= expected
    assert report["failed"] == {}
    assert report["qt"] == [], f"engine imported Qt modules: {report['qt']}"
