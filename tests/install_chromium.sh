#!/usr/bin/env bash
# Installs headless Chromium for tests/report_browser.rs: Debian's `chromium` package, without the
# recommended extras. Idempotent and quiet: does nothing when /usr/bin/chromium is already there.
# Called by tests/report_browser.rs when /usr/bin/chromium is missing, and by .ci/run before the
# tests.
set -euo pipefail
have() { [ -x /usr/bin/chromium ]; }
have && exit 0
source "$(dirname "$0")/apt.sh"
apt_install install_chromium.sh chromium
have || {
    echo "install_chromium.sh: installed, but /usr/bin/chromium is still missing" >&2
    exit 1
}
