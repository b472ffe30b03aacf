"""Where the shared reference material lives: ``../shared`` beside the repository.

CI clones the repository next to ``shared/``, so the location is derived from this file, not
hard-coded; ``GLASSBENCH_SHARED`` overrides it.
"""
from __future__ import annotations

import os
from pathlib import Path

SHARED = Path(os.environ.get("GLASSBENCH_SHARED", Path(__file__).resolve().parents[2] / "shared"))
#: The oracle's SPEC scenes (``public_N.json``).
ORACLE_SPECS = SHARED / "oracle" / "specs"
#: The hard ray-torus cases with 50-digit references.
QUARTIC_CASES = SHARED / "quartic" / "public_cases.json"
