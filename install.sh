#!/usr/bin/env bash
# Sets up everything from nothing: the system GL libraries (Mesa's EGL and OSMesa, which run
# on the CPU when there is no GPU), a virtual environment in .venv, and this package in it
# with its test dependencies and Ray (the `cluster` extra, which the batch tests use). Safe to run again: a step already done is skipped (the pip step
# when .venv was installed from this very pyproject.toml; delete .venv/.install-stamp to
# force it). Quiet unless something goes wrong, when the step's whole output is shown.
set -euo pipefail
cd "$(dirname "$0")"

log=$(mktemp)
trap 'rm -f "$log"' EXIT
quietly() {          # run a step with its output kept aside; show it only if the step fails
    if ! "$@" >"$log" 2>&1; then
        cat "$log" >&2
        echo "install.sh: failed: $*" >&2
        exit 1
    fi
}

packages=(libegl1 libegl-mesa0 libgl1-mesa-dri libosmesa6 libgl1 libglx-mesa0 libx11-6 xvfb xdotool)
missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
    sudo=""; [ "$(id -u)" -eq 0 ] || sudo="sudo"
    echo "install.sh: installing ${missing[*]} (apt-get)"
    quietly $sudo apt-get update -qq
    quietly $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}"
fi

# What the environment was installed from: pyproject.toml and the Python that runs it.
stamp=".venv/.install-stamp"
want=$( { cat pyproject.toml; python3 --version; } | sha256sum | cut -d' ' -f1)
if [ -x .venv/bin/python ] && [ "$(cat "$stamp" 2>/dev/null)" = "$want" ] \
        && .venv/bin/python -c "import renderer, reference" 2>/dev/null; then
    exit 0                                   # up to date: nothing to do
fi
# pip takes a minute or two on a fresh .venv: what it is doing is said as it goes, a line per
# phase (on a terminal, the count of packages collected kept up to date on one line), and
# all of pip's own output only if it fails.
with_progress() {
    local started=$SECONDS collected=0 line
    set +e
    "$@" 2>&1 | tee "$log" | while IFS= read -r line; do
        case "$line" in
            Collecting*|Obtaining*|"Requirement already satisfied"*)
                collected=$((collected + 1))
                [ -t 1 ] && printf '\rinstall.sh: pip: %d packages looked at' "$collected" ;;
            "Installing collected packages"*)
                [ -t 1 ] && printf '\r\033[K'
                echo "install.sh: pip: $collected packages looked at; installing those missing" ;;
        esac
    done
    local status=${PIPESTATUS[0]}
    set -e
    if [ "$status" -ne 0 ]; then
        cat "$log" >&2
        echo "install.sh: failed: $*" >&2
        exit 1
    fi
    echo "install.sh: pip: done in $((SECONDS - started)) s"
}

echo "install.sh: installing the package and its dependencies into .venv (pip)"
[ -x .venv/bin/python ] || quietly python3 -m venv .venv
rm -f "$stamp"
quietly .venv/bin/python -m pip install -q --upgrade pip
with_progress .venv/bin/python -m pip install --progress-bar off -e '.[test,cluster,docs]'
echo "$want" > "$stamp"
