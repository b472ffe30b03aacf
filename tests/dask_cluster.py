"""A real Dask cluster for tests: ``dask scheduler`` and ``dask worker`` processes on 127.0.0.1.

Design rule: nothing is faked. The scheduler and each worker are their own processes, started
with the ``dask`` command of this environment on free loopback ports, with this checkout first
on ``PYTHONPATH`` so workers import the engine under test. Workers run without a nanny (a
killed worker stays dead) and with a death timeout (they quit if the scheduler goes). The
context manager waits for the workers by polling the scheduler with a deadline, and always
terminates every process it started, in a ``finally``.
"""
from __future__ import annotations

import contextlib
import os
import signal
import socket
import subprocess
import sys
from dataclasses import dataclass, field

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DASK = os.path.join(os.path.dirname(sys.executable), "dask")


def free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@dataclass
class RunningCluster:
    """The running cluster: scheduler ``address``, a ``client`` and the worker processes by name."""

    address: str
    client: object
    scheduler: subprocess.Popen
    workers: dict = field(default_factory=dict)
    start_worker: object = None

    def worker_address(self, name: str) -> str:
        info = self.client.scheduler_info(n_workers=-1)["workers"]
        return next(addr for addr, w in info.items() if w.get("name") == name)

    def kill(self, name: str) -> None:
        """SIGKILL one worker (no goodbye to the scheduler) and reap it."""
        proc = self.workers[name]
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=30)

    def replace(self, name: str) -> None:
        """Start a new worker under a dead one's name; wait until the cluster is whole again."""
        self.workers[name] = self.start_worker(name)
        self.client.wait_for_workers(len(self.workers), timeout=60)


@contextlib.contextmanager
def dask_cluster(log_dir, n_workers: int = 2):
    """Start a scheduler and ``n_workers`` single-threaded workers; yield a :class:`RunningCluster`."""
    from distributed import Client
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    path = [REPO] + ([os.environ["PYTHONPATH"]] if os.environ.get("PYTHONPATH") else [])
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(path), OMP_NUM_THREADS="1")
    procs: list = []

    def start(args, name):
        log = open(os.path.join(log_dir, f"{name}.log"), "wb")
        procs.append(subprocess.Popen([DASK, *args], cwd=REPO, env=env, stdout=log,
                                      stderr=subprocess.STDOUT))
        log.close()
        return procs[-1]

    client = None
    try:
        scheduler = start(["scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
                          "scheduler")

        def start_worker(name):
            return start(["worker", address, "--nthreads", "1", "--no-nanny", "--name", name,
                          "--host", "127.0.0.1", "--no-dashboard", "--death-timeout", "30",
                          "--memory-limit", "0"], f"{name}-{len(procs)}")
        workers = {f"w{i}": start_worker(f"w{i}") for i in range(n_workers)}
        client = Client(address, timeout="30s")
        client.wait_for_workers(n_workers, timeout=60)
        yield RunningCluster(address, client, scheduler, workers, start_worker)
    finally:
        if client is not None:
            client.close()
        # Workers first (they would wait for a scheduler that is going), then the scheduler.
        _stop(procs[1:])
        _stop(procs[:1])


def _stop(procs) -> None:
    for proc in procs:
        if proc.poll() is None:
            proc.terminate()
    for proc in procs:
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout=20)
