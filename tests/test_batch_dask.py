"""Batches on a real Dask cluster (a ``dask scheduler`` and two ``dask worker`` processes on
127.0.0.1): frames bit-identical to ``glassbench render``, a worker killed mid-batch, and a
resumed batch that renders only the frames it is missing."""
from __future__ import annotations

import os

import numpy as np
import pytest

from engine import cli
from engine.files.images import read_image
from engine.batch.jobfile import read_job, turntable_job
from engine.batch.manifest import Manifest
from engine.batch.progress import BatchProgress
from engine.batch.run import run_batch
from engine.files.project import load_project, save_project
from engine.tracer.job import render_image
from tests.dask_cluster import dask_cluster

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BORDEAUX = os.path.join(REPO, "resources", "bordeaux.glassbench")
SIZE = ["--width", "24", "--height", "32", "--spp", "2"]


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    with dask_cluster(tmp_path_factory.mktemp("dask-logs"), n_workers=2) as running:
        yield running


def test_a_distributed_turntable_is_bit_identical_to_local_renders(cluster, tmp_path, capsys):
    out = tmp_path / "turn"
    status = cli.main(["turntable", BORDEAUX, "--frames", "4", "-o", str(out), "--format", "exr",
                       *SIZE, "--scheduler", cluster.address, "--quiet"])
    assert status == 0, capsys.readouterr().err
    names = sorted(p.name for p in out.iterdir())
    assert names == ["contact_sheet.png", "frame_0000.exr", "frame_0001.exr", "frame_0002.exr",
                     "frame_0003.exr", "manifest.json", "summary.csv", "summary.json"]
    job = turntable_job(BORDEAUX, 4, str(out), width=24, height=32, spp=2, format="exr")
    _, assets = load_project(BORDEAUX)
    for frame in job.frames():
        # The same camera through the ordinary single-machine command: a project of that frame.
        project = tmp_path / f"{frame.view.name}.glassbench"
        save_project(project, frame.design, assets)
        local = tmp_path / f"local_{frame.view.name}.exr"
        assert cli.main(["render", str(project), "-o", str(local), *SIZE]) == 0
        remote = read_image(str(out / frame.relpath))
        assert remote.shape == (32, 24, 3)
        assert np.array_equal(remote, read_image(str(local))), f"{frame.relpath} differs from a local render"
    images = [read_image(str(out / f"frame_{k:04d}.exr")) for k in range(4)]
    assert not np.array_equal(images[0], images[1]), "the turntable moved"
    workers = {e["worker"] for e in Manifest(str(out)).frames.values()}
    assert len(workers) == 2 and all(w.startswith("tcp://127.0.0.1:") for w in workers)


class StopAfter(BatchProgress):
    """Interrupts the batch (as Ctrl-C would) once ``n`` frames are written."""

    def __init__(self, n):
        self.n, self.done = n, []

    def frame_done(self, relpath, seconds, worker):
        self.done.append(relpath)
        if len(self.done) == self.n:
            raise KeyboardInterrupt


JOB = """\
output = "out"
width = 24
height = 32
spp = 1
turntable = 2
[[projects]]
file = "{project}"
  [[projects.variants]]
  name = "a"
  [[projects.variants]]
  name = "b"
  glass_tint = [0.001, 0.004, 0.01]
"""


def test_an_interrupted_batch_resumes_with_only_the_missing_frames(cluster, tmp_path):
    job_file = tmp_path / "job.toml"
    job_file.write_text(JOB.format(project=BORDEAUX))
    job = read_job(job_file)
    with pytest.raises(KeyboardInterrupt):
        run_batch(job, scheduler=cluster.address, progress=StopAfter(2))
    out = tmp_path / "out"
    first = sorted(Manifest(str(out)).frames)
    assert len(first) == 2
    on_disk = sorted(str(p.relative_to(out)) for p in out.rglob("*.png"))
    assert on_disk == first, "only finished frames are on disk, and no partial files"
    assert not list(out.rglob(".partial-*"))
    before = {rel: os.stat(out / rel) for rel in first}

    report = run_batch(read_job(job_file), scheduler=cluster.address)
    all_frames = ["a/frame_0000.png", "a/frame_0001.png", "b/frame_0000.png", "b/frame_0001.png"]
    assert sorted(report.rendered) == sorted(set(all_frames) - set(first))
    assert sorted(report.skipped) == first
    for rel, st in before.items():
        now = os.stat(out / rel)
        assert (now.st_ino, now.st_mtime_ns) == (st.st_ino, st.st_mtime_ns), f"{rel} was rewritten"
    assert sorted(Manifest(str(out)).frames) == all_frames

    # A changed override and a damaged file render again; nothing else does.
    job_file.write_text(JOB.format(project=BORDEAUX).replace("0.001, 0.004, 0.01", "0.002, 0.004, 0.01"))
    (out / "a/frame_0001.png").write_bytes(b"damaged")
    again = run_batch(read_job(job_file), scheduler=cluster.address)
    assert sorted(again.rendered) == ["a/frame_0001.png", "b/frame_0000.png", "b/frame_0001.png"]
    assert read_image(str(out / "a/frame_0001.png")).shape == (32, 24, 3)


class KillBusyWorker(BatchProgress):
    """When the first frame is written, SIGKILLs a worker that is rendering one (any worker if
    none is busy by then: the batch must lose no frame either way)."""

    def __init__(self, cluster):
        self.cluster, self.killed = cluster, None
        self.events = []

    def frame_progress(self, relpath, fraction, tiles):
        self.events.append((relpath, fraction, tiles))

    def frame_done(self, relpath, seconds, worker):
        if self.killed is not None:
            return
        busy = {addr for addr, keys in self.cluster.client.processing().items() if keys}
        names = sorted(self.cluster.workers)
        name = next((n for n in names if self.cluster.worker_address(n) in busy), names[0])
        self.killed = (name, self.cluster.worker_address(name))
        self.cluster.kill(name)


def test_a_worker_killed_mid_batch_costs_only_its_frames(cluster, tmp_path):
    # frames long enough (a few tenths of a second) that others are still rendering or queued
    # when the first one is written: 24 x 32 px at 1 spp took ~10 ms, all could be done by then
    job = turntable_job(BORDEAUX, 8, str(tmp_path / "turn"), width=48, height=64, spp=2, format="exr")
    killer = KillBusyWorker(cluster)
    try:
        report = run_batch(job, scheduler=cluster.address, progress=killer)
        name, address = killer.killed
        assert cluster.workers[name].poll() is not None, "the worker is dead"
        assert len(cluster.client.scheduler_info()["workers"]) == 1
    finally:
        if killer.killed is not None:
            cluster.replace(killer.killed[0])  # whole again for whatever runs next
    assert sorted(report.rendered) == [f"frame_{k:04d}.exr" for k in range(8)]
    assert killer.events and all(0.0 <= f <= 1.0 and t >= 0 for _, f, t in killer.events), \
        "tile progress came from the workers as Dask events"
    entries = Manifest(job.output).frames
    assert sum(e["worker"] != address for e in entries.values()) >= 3
    _, assets = load_project(BORDEAUX)
    for frame in job.frames():
        local = render_image(frame.design, assets, threads=2)
        assert np.array_equal(read_image(os.path.join(job.output, frame.relpath)), local), frame.relpath
