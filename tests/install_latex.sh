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
source "$(dirname "$0")/apt.sh"
apt_install install_latex.sh texlive-latex-base texlive-latex-recommended
have || {
    echo "install_latex.sh: installed, but pdflatex, booktabs.sty or longtable.sty still missing" >&2
    exit 1
}
