#!/usr/bin/env bash
# Installs headless Chromium for tests/report_browser.rs: Debian's `chromium` package, without the
# recommended extras. Idempotent and quiet: does nothing when /usr/bin/chromium is already there.
# Called by tests/report_browser.rs when /usr/bin/chromium is missing, and by .ci/run before the
# tests.
set -euo pipefail

have() {
    [ -x /usr/bin/chromium ]
}
have && exit 0

if ! command -v apt-get >/dev/null 2>&1; then
    echo "install_chromium.sh: /usr/bin/chromium is missing and this is not a Debian/Ubuntu system;" \
        "install Chromium so that /usr/bin/chromium runs headless" >&2
    exit 1
fi
sudo=""
if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null 2>&1; then sudo="sudo -n"; else
        echo "install_chromium.sh: chromium is missing; run as root: apt-get install chromium" >&2
        exit 1
    fi
fi
export DEBIAN_FRONTEND=noninteractive
# Wait for another apt (a parallel test, an unattended upgrade) instead of failing on its lock.
lock=(-o DPkg::Lock::Timeout=600)
# Quiet: apt's chatter is shown only if the install fails.
log=$(mktemp)
trap 'rm -f "$log"' EXIT
if ! { $sudo apt-get "${lock[@]}" -qq update &&
    $sudo apt-get "${lock[@]}" -qq install -y --no-install-recommends chromium; } >"$log" 2>&1; then
    cat "$log" >&2
    echo "install_chromium.sh: apt-get failed" >&2
    exit 1
fi
have || {
    echo "install_chromium.sh: installed, but /usr/bin/chromium is still missing" >&2
    exit 1
}
