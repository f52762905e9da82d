#!/usr/bin/env bash
# Render the LaTeX convergence tables of the 003 Fig 10 ladder, below the paper's own values, to
# one PNG (docs/guide.md's analysis/figures/003_fig10_table.png):
#
#   bash analysis/render_fig10_table.sh [OUT_DIR] [PNG]
#
# Runs sweeps/003_fig10_ladder.toml into OUT_DIR (default out/003-fig10) unless it holds runs,
# summarizes it with the default columns, typesets summary/convergence.tex unchanged on one tall
# page (pdflatex), rasterises it (pdftoppm) and trims the margin (Pillow, a matplotlib
# dependency). Needs pdflatex (tests/install_latex.sh) and pdftoppm (Debian: poppler-utils).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/003-fig10}
png=${2:-analysis/figures/003_fig10_table.png}
for tool in pdflatex pdftoppm; do
    command -v "$tool" >/dev/null || {
        echo "render_fig10_table.sh: $tool missing (pdflatex: bash tests/install_latex.sh; pdftoppm: apt-get install poppler-utils)" >&2
        exit 1
    }
done
cargo build --release --quiet
bin=target/release/contact-sweep
if ! ls "$out"/runs/*.parquet >/dev/null 2>&1; then
    "$bin" run sweeps/003_fig10_ladder.toml --out "$out" --no-summary >/dev/null
fi
"$bin" summarize "$out" >/dev/null

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp "$out/summary/convergence.tex" "$work/"
# The paper's figures are contract §6's (003 §4.1.2e, Fig 10): l2(τ;H1) at h = τ = 1/4 … 1/256.
cat >"$work/render.tex" <<'EOF'
\documentclass[10pt]{article}
\usepackage[paperwidth=17cm,paperheight=80cm,margin=6mm]{geometry}
\usepackage{booktabs}
% every table on the one page, in order
\setcounter{topnumber}{20}\setcounter{totalnumber}{20}
\renewcommand{\topfraction}{1}\renewcommand{\textfraction}{0}
\pagestyle{empty}
\begin{document}
\begin{table}[htbp]
  \centering\small
  \caption{Paper 003, section 4.1.2e, Fig 10, as printed (contract section 6): $u$ in $l^2(\tau;H^1)$ on
    the ladder $h = \tau$ ($\nu = 1$). The tables below are \texttt{contact-sweep summarize}'s
    \texttt{convergence.tex} for \texttt{sweeps/003\_fig10\_ladder.toml}, unchanged.}
  \begin{tabular}{lrrrr}
    \toprule
    method & $h = 1/4$ & $1/16$ & $1/64$ & $1/256$ \\
    \midrule
    mixed + CN & 2.373 & 1.470 & 3.166 & 4.610 \\
    Nitsche-Hybrid & 0.7243 & 0.5428 & 0.3664 & 0.2347 \\
    mod3 + CN & 0.7641 & 0.5186 & 0.3337 & 0.2224 \\
    zero-contact + CN & 1.534 & 0.7234 & 0.3667 & 0.2155 \\
    \bottomrule
  \end{tabular}
\end{table}
\input{convergence.tex}
\end{document}
EOF
(cd "$work" && pdflatex -interaction=nonstopmode -halt-on-error render.tex >/dev/null) || {
    tail -30 "$work/render.log" >&2
    exit 1
}
pages=$(grep -o 'Output written on render.pdf ([0-9]* page' "$work/render.log" | grep -o '[0-9]* page' | cut -d' ' -f1)
[ "$pages" = 1 ] || { echo "render_fig10_table.sh: $pages pages, expected 1" >&2; exit 1; }
pdftoppm -r 130 -png -singlefile "$work/render.pdf" "$work/page"
python3 - "$work/page.png" "$png" <<'EOF'
import sys
from PIL import Image, ImageChops
img = Image.open(sys.argv[1]).convert("L")
box = ImageChops.invert(img).getbbox()  # the inked area
pad = 20
box = (max(box[0] - pad, 0), max(box[1] - pad, 0), min(box[2] + pad, img.width), min(box[3] + pad, img.height))
img.crop(box).save(sys.argv[2], optimize=True)
print(f"{sys.argv[2]}: {box[2] - box[0]}x{box[3] - box[1]} px")
EOF
