#!/usr/bin/env bash
# Installs Gmsh (the `gmsh` command) for regenerating the test meshes of sweeps/meshes/: the
# official `gmsh` Python wheel via pip (it ships the gmsh binary and its libraries), falling back
# to Debian's `gmsh` package (Debian's own python3 refuses the pip install, PEP 668).
# Idempotent and quiet: does nothing when `gmsh` is already on PATH.
set -euo pipefail
command -v gmsh >/dev/null 2>&1 && exit 0
if command -v python3 >/dev/null 2>&1 && python3 -m pip install -q gmsh >/dev/null 2>&1; then
    hash -r
    command -v gmsh >/dev/null 2>&1 && exit 0
fi
source "$(dirname "$0")/apt.sh"
apt_install install_gmsh.sh gmsh
command -v gmsh >/dev/null 2>&1 || {
    echo "install_gmsh.sh: installed, but gmsh is still not on PATH" >&2
    exit 1
}
