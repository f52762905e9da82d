#!/usr/bin/env bash
# The README's test command: every test, the Python ones included, on a stock machine.
#
# Debian's and Ubuntu's own python3 refuse `pip install` outside a virtual environment (PEP 668,
# "externally-managed-environment"), so the analysis scripts' packages cannot go into the
# system Python. This script keeps them in a virtual environment inside the tree, `.venv/`
# (git-ignored): it creates it with the first `python3` on PATH when missing (installing
# Debian's python3-venv first when `python3 -m venv` cannot work and we are root), installs
# analysis/requirements.txt there when that file changed since the last install, and runs
# `cargo test --release` with `.venv/bin` first on PATH — so the tests that call `python3`
# (tests/analysis.rs, tests/readers.rs, …) use the environment's interpreter. GetFEM's checks
# keep calling /usr/bin/python3 by its path: Debian's python3-getfem lives in the system Python.
#
# Arguments are passed on to cargo test (`scripts/test.sh --test analysis`).
# VENV=DIR chooses another environment folder.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=${VENV:-.venv}
case $venv in /*) ;; *) venv="$PWD/$venv" ;; esac
say() { echo "scripts/test.sh: $*" >&2; }

command -v python3 >/dev/null 2>&1 || {
    say "python3 is missing: install Python 3.11 or newer (Debian/Ubuntu: apt-get install python3 python3-venv)"
    exit 1
}

# `python3 -m venv` needs ensurepip, which Debian and Ubuntu ship apart in python3-venv.
ensure_venv_module() {
    python3 -c 'import venv, ensurepip' >/dev/null 2>&1 && return 0
    if [ "$(id -u)" -eq 0 ] && command -v apt-get >/dev/null 2>&1; then
        say "python3 cannot create a virtual environment (no ensurepip): installing python3-venv"
        local log
        log=$(mktemp)
        export DEBIAN_FRONTEND=noninteractive
        if ! { apt-get -o DPkg::Lock::Timeout=600 -qq update &&
            apt-get -o DPkg::Lock::Timeout=600 -qq install -y --no-install-recommends python3-venv; } >"$log" 2>&1; then
            cat "$log" >&2
            rm -f "$log"
            say "apt-get install python3-venv failed"
            exit 1
        fi
        rm -f "$log"
        python3 -c 'import venv, ensurepip' >/dev/null 2>&1 && return 0
        say "python3-venv is installed but $(command -v python3) still has no ensurepip"
        exit 1
    fi
    say "$(command -v python3) cannot create a virtual environment (the module ensurepip is missing)."
    say "On Debian/Ubuntu run as root: apt-get install python3-venv — then run scripts/test.sh again."
    exit 1
}

# A usable environment has a python that starts and a pip; anything else is made again (a
# `python3 -m venv` interrupted, or one whose base interpreter was removed).
if ! { [ -x "$venv/bin/python3" ] && "$venv/bin/python3" -m pip --version >/dev/null 2>&1; }; then
    ensure_venv_module
    rm -rf "$venv"
    # The interpreter itself, not a link or shim to it, so the environment outlives a PATH entry.
    py=$(python3 -c 'import os, sys; print(os.path.realpath(sys.executable))')
    say "creating the virtual environment $venv with $py ($(python3 --version 2>&1))"
    "$py" -m venv "$venv"
fi

# Install the requirements when they changed since the last successful install (a stamp of
# requirements.txt's content in the environment), so a second run needs no network.
stamp="$venv/.requirements.txt"
if ! cmp -s analysis/requirements.txt "$stamp"; then
    say "installing analysis/requirements.txt into $venv"
    "$venv/bin/python3" -m pip install --quiet --disable-pip-version-check -r analysis/requirements.txt
    cp analysis/requirements.txt "$stamp"
fi

export VIRTUAL_ENV="$venv"
export PATH="$VIRTUAL_ENV/bin:$PATH"
hash -r
exec cargo test --release "$@"
