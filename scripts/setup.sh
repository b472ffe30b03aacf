#!/usr/bin/env bash
# Set up everything glassbench needs on a fresh Debian/Ubuntu machine, idempotently:
# the system libraries Qt, VTK and Xvfb need and Debian's chromium and node (apt-get, only when
# missing), a virtual environment in .venv with glassbench and its test tools (pip), then the
# Node packages of web/package-lock.json in web/node_modules (npm ci: <model-viewer> for
# glassbench share, the glTF validator and playwright-core for the tests).
set -euo pipefail
cd "$(dirname "$0")/.."

DEB_PACKAGES=(xvfb xauth libgl1 libegl1 libgl1-mesa-dri libglu1-mesa libxkbcommon-x11-0
  libxcb-cursor0 libxcb-icccm4 libxcb-image0 libxcb-keysyms1 libxcb-randr0
  libxcb-render-util0 libxcb-shape0 libxcb-xinerama0 libxcb-xkb1 libdbus-1-3
  libfontconfig1 libglib2.0-0 libxrender1 libxi6 libxext6 libsm6 libice6 fonts-dejavu-core
  chromium)
# node and npm: Debian's nodejs and npm, unless a node with its npm is there already.
command -v node >/dev/null 2>&1 || DEB_PACKAGES+=(nodejs)
command -v npm >/dev/null 2>&1 || DEB_PACKAGES+=(npm)

if command -v dpkg >/dev/null 2>&1; then
  missing=()
  for p in "${DEB_PACKAGES[@]}"; do
    dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
  done
  if [ ${#missing[@]} -gt 0 ]; then
    SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
    echo "setup: installing Debian packages: ${missing[*]}"
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}" >/dev/null
  fi
fi

PY=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
  echo "setup: creating .venv"
  "$PY" -m venv .venv
fi
# Reinstall only when pyproject.toml changed since the last successful install.
stamp=.venv/.glassbench-installed
if [ ! -f "$stamp" ] || [ pyproject.toml -nt "$stamp" ]; then
  echo "setup: installing Python packages into .venv (first time takes a few minutes)"
  .venv/bin/python -m pip install -q --upgrade pip
  .venv/bin/python -m pip install -q -e ".[test]"
  touch "$stamp"
fi

# Node packages, pinned by web/package-lock.json; reinstalled only when the lock file changed.
npm_stamp=web/node_modules/.glassbench-installed
if [ ! -f "$npm_stamp" ] || [ web/package-lock.json -nt "$npm_stamp" ]; then
  echo "setup: installing Node packages into web/node_modules"
  (cd web && npm ci --no-audit --no-fund --loglevel=error)
  touch "$npm_stamp"
fi
