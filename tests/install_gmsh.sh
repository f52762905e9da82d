#!/usr/bin/env bash
# Installs Gmsh (the `gmsh` command) for regenerating the test meshes of sweeps/meshes/: the
# official `gmsh` Python wheel via pip (it ships the gmsh binary and its libraries), falling back
# to Debian's `gmsh` package. Idempotent and quiet: does nothing when `gmsh` is already on PATH.
set -euo pipefail
command -v gmsh >/dev/null 2>&1 && exit 0
log=$(mktemp)
trap 'rm -f "$log"' EXIT
if command -v python3 >/dev/null 2>&1 && python3 -m pip install -q gmsh >"$log" 2>&1; then
    hash -r
    command -v gmsh >/dev/null 2>&1 && exit 0
fi
if command -v apt-get >/dev/null 2>&1; then
    sudo=""
    if [ "$(id -u)" -ne 0 ]; then sudo="sudo -n"; fi
    export DEBIAN_FRONTEND=noninteractive
    lock=(-o DPkg::Lock::Timeout=600)
    if { $sudo apt-get "${lock[@]}" -qq update &&
        $sudo apt-get "${lock[@]}" -qq install -y --no-install-recommends gmsh; } >>"$log" 2>&1; then
        command -v gmsh >/dev/null 2>&1 && exit 0
    fi
fi
cat "$log" >&2
echo "install_gmsh.sh: could not install gmsh (pip wheel or Debian package)" >&2
exit 1
