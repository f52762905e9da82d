#!/usr/bin/env bash
# Installs GetFEM's Python interface (Debian's python3-getfem, with numpy and scipy) for
# tests/getfem_disc.rs: the engine against an independent GetFEM implementation of the same
# discretisation on the same Gmsh file. Idempotent and quiet: nothing to do when Debian's
# python3 already imports getfem and scipy.
set -euo pipefail
have() { /usr/bin/python3 -c 'import getfem, scipy' >/dev/null 2>&1; }
have && exit 0
source "$(dirname "$0")/apt.sh"
apt_install install_getfem.sh python3-getfem python3-numpy python3-scipy
have || {
    echo "install_getfem.sh: installed, but /usr/bin/python3 still cannot import getfem" >&2
    exit 1
}
