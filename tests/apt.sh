#!/usr/bin/env bash
# Sourced by the tests' install scripts (tests/install_*.sh): the one way a test installs a
# Debian package. As root, or with `sudo -n`; waits for another apt (a parallel test, an
# unattended upgrade) instead of failing on its lock; quiet — apt's and debconf's chatter is
# shown only if the install fails.
#
#   apt_install WHO PACKAGE...   (WHO names the calling script in messages)

apt_install() {
    local who=$1
    shift
    if ! command -v apt-get >/dev/null 2>&1; then
        echo "$who: this is not a Debian/Ubuntu system; install $* (or their equivalents)" >&2
        return 1
    fi
    local sudo=""
    if [ "$(id -u)" -ne 0 ]; then
        if command -v sudo >/dev/null 2>&1; then sudo="sudo -n"; else
            echo "$who: run as root: apt-get install $*" >&2
            return 1
        fi
    fi
    export DEBIAN_FRONTEND=noninteractive
    local lock=(-o DPkg::Lock::Timeout=600)
    local log
    log=$(mktemp)
    if ! { $sudo apt-get "${lock[@]}" -qq update &&
        $sudo apt-get "${lock[@]}" -qq install -y --no-install-recommends "$@"; } >"$log" 2>&1; then
        cat "$log" >&2
        rm -f "$log"
        echo "$who: apt-get install $* failed" >&2
        return 1
    fi
    rm -f "$log"
}
