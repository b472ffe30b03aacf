#!/usr/bin/env bash
# Optional: the peer renderer of `python -m benchmarks.peer` (Mitsuba 3, llvm_ad_rgb variant).
# Its LLVM back end needs Debian's libllvm19 (the system's LLVM 15 aborts with "Cannot select
# fminimum"); benchmarks.peer finds libLLVM-19.so and sets DRJIT_LIBLLVM_PATH itself.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
if command -v dpkg >/dev/null 2>&1 && ! dpkg -s libllvm19 >/dev/null 2>&1; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "setup_peer: installing libllvm19"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq libllvm19 >/dev/null
fi
.venv/bin/python -m pip install -q -e ".[test,peer]"
.venv/bin/python -c "from benchmarks.peer import mitsuba_available as m; w = m(); print('Mitsuba 3 ready' if w is None else w)"
