#!/usr/bin/env bash
# Installs Siconos 4.4's Python interface (Debian's python3-siconos, with numpy) for
# tests/friction_campaign.rs's Moreau–Jean comparison (tests/siconos/block_moreau_jean.py).
# Idempotent and quiet: nothing to do when Debian's python3 already imports siconos.
set -euo pipefail
py=/usr/bin/python3
if [ -x "$py" ] && "$py" -c 'import siconos.kernel, numpy' >/dev/null 2>&1; then
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
            python3-siconos python3-numpy; } >>"$log" 2>&1; then
        "$py" -c 'import siconos.kernel, numpy' >/dev/null 2>&1 && exit 0
    fi
fi
cat "$log" >&2
echo "install_siconos.sh: could not install python3-siconos (Debian package)" >&2
exit 1
