#!/usr/bin/env bash
# Installs pdflatex for tests/latex.rs: Debian's texlive-latex-base (LaTeX, longtable) and
# texlive-latex-recommended (booktabs), without the recommended extras (fonts, docs).
# Idempotent and quiet: does nothing when pdflatex and both packages are already there.
# Called by tests/latex.rs when pdflatex is not on PATH, and by .ci/run before the tests.
set -euo pipefail

have() {
    command -v pdflatex >/dev/null 2>&1 &&
        kpsewhich booktabs.sty >/dev/null 2>&1 &&
        kpsewhich longtable.sty >/dev/null 2>&1
}
have && exit 0

if ! command -v apt-get >/dev/null 2>&1; then
    echo "install_latex.sh: pdflatex is missing and this is not a Debian/Ubuntu system;" \
        "install a TeX distribution with booktabs and longtable" >&2
    exit 1
fi
sudo=""
if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null 2>&1; then sudo="sudo -n"; else
        echo "install_latex.sh: pdflatex is missing; run as root: apt-get install" \
            "texlive-latex-base texlive-latex-recommended" >&2
        exit 1
    fi
fi
export DEBIAN_FRONTEND=noninteractive
# Wait for another apt (a parallel test, an unattended upgrade) instead of failing on its lock.
lock=(-o DPkg::Lock::Timeout=600)
# Quiet: apt's and debconf's chatter is shown only if the install fails.
log=$(mktemp)
trap 'rm -f "$log"' EXIT
if ! { $sudo apt-get "${lock[@]}" -qq update &&
    $sudo apt-get "${lock[@]}" -qq install -y --no-install-recommends \
        texlive-latex-base texlive-latex-recommended; } >"$log" 2>&1; then
    cat "$log" >&2
    echo "install_latex.sh: apt-get failed" >&2
    exit 1
fi
have || {
    echo "install_latex.sh: installed, but pdflatex, booktabs.sty or longtable.sty still missing" >&2
    exit 1
}
