"""The peak resident memory of a process of its own, as tests that bound memory measure it.

Not ``getrusage``: on Linux a child's ``ru_maxrss`` (``RUSAGE_SELF``, ``RUSAGE_CHILDREN`` and
``os.wait4`` alike) keeps the high-water mark of the address space it was forked from, so a child
of a pytest process that has grown to 2 GiB reports 2 GiB however little it uses itself (CI failed
``test_export_limits`` so, twice). ``VmHWM`` in ``/proc/self/status`` is the high-water mark of
the address space ``exec`` gave the child: its own.
"""
from __future__ import annotations


def peak_rss_bytes() -> int:
    """This process's own peak resident memory since its ``exec`` (bytes; -1 if unknown)."""
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) * 1024  # the kernel reports kB
    return -1


#: Python source that, prefixed to a child's code, writes its peak (bytes) to the file named by
#: the environment variable ``GLASSBENCH_PEAK_FILE`` when the child exits (``SystemExit`` too).
REPORT_AT_EXIT = (
    "import atexit as _atexit, os as _os\n"
    "from tests.peak_memory import peak_rss_bytes as _peak\n"
    "_atexit.register(lambda: open(_os.environ['GLASSBENCH_PEAK_FILE'], 'w').write(str(_peak())))\n"
)
