#!/usr/bin/env bash
# Installs GetFEM's Python interface (Debian's python3-getfem, with numpy and scipy) for
# tests/getfem_disc.rs: the engine against an independent GetFEM implementation of the same
# discretisation on the same Gmsh file. Idempotent and quiet: nothing to do when Debian's
# python3 already imports getfem and scipy.
set -euo pipefail
py=/usr/bin/python3
if [ -x "$py" ] && "$py" -c 'import getfem, scipy' >/dev/null 2>&1; then
    exit 0
fi
log=$(mktemp)
trap 'rm -f "$log"' EXIT
if command -v apt-get >/dev/null 2>&1; then
    sudo=""
    if [ "$(id -u)" -ne 0 ]; then sudo="sudo -n"; fi
    export DEBIAN_FRONTEND=noninteractive
    lock=(-o DPkg::Lock::Timeout=600)
    if { $sudo apt-get "${lock[@]}" -qq update &&
        $sudo apt-get "${lock[@]}" -qq install -y --no-install-recommends \
            python3-getfem python3-numpy python3-scipy; } >>"$log" 2>&1; then
        "$py" -c 'import getfem, scipy' >/dev/null 2>&1 && exit 0
    fi
fi
cat "$log" >&2
echo "install_getfem.sh: could not install python3-getfem (Debian package)" >&2
exit 1
