#!/usr/bin/env bash
# Sets up everything from nothing: the system GL libraries (Mesa's EGL and OSMesa, which run
# on the CPU when there is no GPU), a virtual environment in .venv, and this package in it
# with its test dependencies. Safe to run again.
set -euo pipefail
cd "$(dirname "$0")"

packages=(libegl1 libegl-mesa0 libgl1-mesa-dri libosmesa6 libgl1 libglx-mesa0 libx11-6 xvfb xdotool)
missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
    sudo=""; [ "$(id -u)" -eq 0 ] || sudo="sudo"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${missing[@]}"
fi

python3 -m venv .venv
.venv/bin/python -m pip install -q --upgrade pip
.venv/bin/python -m pip install -q -e '.[test]'
