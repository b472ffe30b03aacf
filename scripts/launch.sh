#!/usr/bin/env bash
# Set up (first run only) and open the workbench on the bundled sample project.
# Extra arguments go to `glassbench` (e.g. a project path, or --screenshot OUT.png).
# With no display it renders the sample to a PNG instead and prints where.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
exec .venv/bin/glassbench "$@"
