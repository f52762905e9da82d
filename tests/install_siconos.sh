#!/usr/bin/env bash
# Installs Siconos 4.4's Python interface (Debian's python3-siconos, with numpy) for
# tests/friction_campaign.rs's Moreau–Jean comparison (tests/siconos/block_moreau_jean.py).
# Idempotent and quiet: nothing to do when Debian's python3 already imports siconos.
set -euo pipefail
have() { /usr/bin/python3 -c 'import siconos.kernel, numpy' >/dev/null 2>&1; }
have && exit 0
source "$(dirname "$0")/apt.sh"
apt_install install_siconos.sh python3-siconos python3-numpy
have || {
    echo "install_siconos.sh: installed, but /usr/bin/python3 still cannot import siconos" >&2
    exit 1
}
