"""What writes leave behind (issue 11, class 7): killed saves, backups, links, failed cleanups,
autosave copies and image exports. Every write replaces its file whole or not at all, and what a
killed writer left is removed by the next write of the same file."""
from __future__ import annotations

import dataclasses
import errno
import os
import stat
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from engine.errors import ProjectError
from engine.io import atomic
from engine.files.project import load_project, save_project
from tests.test_fuzz_files import cylinder_design

FUZZ = settings(max_examples=60, deadline=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])

# The child saves over an existing project and is killed (SIGKILL) at its k-th file step.
KILLED_SAVE = r"""
import os, signal, sys, zipfile, dataclasses
sys.path.insert(0, sys.argv[3])
from engine.io import atomic
from engine.files.project import save_project
from tests.test_fuzz_files import cylinder_design
steps, k = [0], int(sys.argv[2])
def killing(fn):
    def step(*a, **kw):
        if steps[0] == k:
            os.kill(os.getpid(), signal.SIGKILL)
        steps[0] += 1
        return fn(*a, **kw)
    return step
zipfile.ZipFile.writestr = killing(zipfile.ZipFile.writestr)
atomic._fsync_file = killing(atomic._fsync_file)
atomic.keep_backup = killing(atomic.keep_backup)
os.chmod, os.replace = killing(os.chmod), killing(os.replace)
save_project(sys.argv[1], dataclasses.replace(cylinder_design(), name="second"), {"a.bin": b"x" * 3000000})
print("finished")
"""
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def temporaries(folder):
    return sorted(n for n in os.listdir(folder) if ".tmp" in n)


@pytest.mark.parametrize("step", range(8))
def test_a_save_killed_at_any_step_leaves_an_openable_project_and_its_litter_is_swept(tmp_path, step):
    path = tmp_path / "p.glassbench"
    save_project(path, cylinder_design(), {})
    run = subprocess.run([sys.executable, "-c", KILLED_SAVE, str(path), str(step), ROOT],
                         capture_output=True, text=True, cwd=ROOT)
    assert run.returncode == -9, run.stderr  # every step up to the final rename was reached
    assert temporaries(tmp_path), "the killed save left nothing to sweep"
    design, _ = load_project(path)  # old or new, never broken
    assert design.name in ("Cylinder", "second")
    save_project(path, cylinder_design(name="third"), {})  # the next save sweeps what was left
    assert temporaries(tmp_path) == []
    assert load_project(path)[0].name == "third"


@FUZZ
@given(names=st.lists(st.tuples(st.sampled_from(["own", "dead", "alive", "elsewhere", "legacy-old",
                                                 "legacy-new", "other", "other-bak"]), st.integers(0, 99)),
                      max_size=12, unique=True))
def test_only_the_litter_of_writers_that_are_gone_is_removed(tmp_path_factory, names):
    folder = tmp_path_factory.mktemp("litter")
    target = str(folder / "p.glassbench")
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True).stdout.strip()
    alive = str(os.getppid())
    made, stale = [], set()
    for kind, n in names:
        token = f"{n:08x}"
        host = atomic.HOST
        name = {"own": f".p.glassbench.{host}.{os.getpid()}-{token}.tmp",
                "dead": f".p.glassbench.{host}.{dead}-{token}.tmp.png",
                "alive": f".p.glassbench.bak.{host}.{alive}-{token}.tmp",
                "elsewhere": f".p.glassbench.other-host.{dead}-{token}.tmp",
                "legacy-old": f".glassbench-old{n:05d}.tmp", "legacy-new": f".glassbench-bak-new{n:05d}",
                "other": f".q.glassbench.{dead}-{token}.tmp", "other-bak": f"p.glassbench.{dead}.tmp"}[kind]
        (folder / name).write_bytes(b"litter")
        if kind == "legacy-old":
            os.utime(folder / name, (1.0, 1.0))
        made.append(name)
        if kind in ("dead", "legacy-old"):
            stale.add(name)
    removed = {os.path.basename(p) for p in atomic.remove_stale_temporaries(target)}
    assert removed == stale
    assert sorted(os.listdir(folder)) == sorted(set(made) - stale)


def test_backup_keeps_the_permission_bits_of_the_file_it_backs_up(tmp_path):
    path = tmp_path / "p.glassbench"
    save_project(path, cylinder_design(), {})
    os.chmod(path, 0o640)
    save_project(path, cylinder_design(name="second"), {})
    assert stat.S_IMODE(os.stat(path).st_mode) == 0o640
    assert stat.S_IMODE(os.stat(str(path) + ".bak").st_mode) == 0o640


def test_saving_through_a_symbolic_link_keeps_the_link(tmp_path):
    real_dir = tmp_path / "real"
    real_dir.mkdir()
    real = real_dir / "p.glassbench"
    save_project(real, cylinder_design(), {})
    link = tmp_path / "link.glassbench"
    link.symlink_to(real)
    save_project(link, cylinder_design(name="through the link"), {})
    assert link.is_symlink() and os.readlink(link) == str(real)
    assert load_project(real)[0].name == "through the link"
    assert (real_dir / "p.glassbench.bak").exists() and temporaries(real_dir) == []


def test_a_failed_write_whose_cleanup_also_fails_is_one_project_error(tmp_path, monkeypatch):
    path = tmp_path / "p.glassbench"
    save_project(path, cylinder_design(), {})
    before = path.read_bytes()

    def full_disk(*a, **kw):
        raise OSError(errno.ENOSPC, "No space left on device")
    monkeypatch.setattr("zipfile.ZipFile.writestr", full_disk)
    monkeypatch.setattr(atomic.os, "unlink", full_disk)
    with pytest.raises(ProjectError, match="No space left on device"):
        save_project(path, cylinder_design(name="second"), {})
    monkeypatch.undo()
    assert path.read_bytes() == before


def test_a_failed_image_write_keeps_the_previous_image(tmp_path):
    from engine.files.images import save_image
    path = tmp_path / "render.png"
    save_image(path, np.full((4, 4, 3), 0.5, np.float32))
    before = path.read_bytes()
    with pytest.raises(OSError, match="disk full"):
        with atomic.replacing(path, suffix=".png") as tmp:
            with open(tmp, "wb") as fh:
                fh.write(b"\x89PNG truncated")
            raise OSError("disk full")
    assert path.read_bytes() == before and temporaries(tmp_path) == []
    save_image(path, np.zeros((2, 2, 3), np.float32))  # and a real rewrite replaces it whole
    assert path.read_bytes() != before and temporaries(tmp_path) == []


def test_autosave_discard_leaves_nothing_behind(gui_paths, qapp):
    from app.document import Autosaver, recovery_dir
    saver = Autosaver()
    saver.write(cylinder_design(), {}, None)
    saver.write(dataclasses.replace(cylinder_design(), name="later"), {}, None)
    assert load_project(saver.path)[0].name == "later"
    (recovery_dir() / (saver.path.name + ".bak")).write_bytes(b"from an older version")
    saver.discard()
    assert list(recovery_dir().iterdir()) == []


def test_image_export_from_the_window_is_atomic(make_window, tmp_path, monkeypatch):
    from PySide6.QtGui import QImage
    w = make_window()
    path = tmp_path / "shot.png"
    path.write_bytes(b"previous image")
    monkeypatch.setattr(w.preview, "image", lambda: QImage())  # a null image cannot be saved
    assert not w.files.export_image(str(path))
    assert path.read_bytes() == b"previous image" and temporaries(tmp_path) == []
    assert w.dialogs.errors and w.dialogs.errors[-1][0] == "Cannot export image"
