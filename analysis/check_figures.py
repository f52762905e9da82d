#!/usr/bin/env python3
"""Check the figures in a folder: present, readable, not blank.

    python3 analysis/check_figures.py FIGDIR [--expect NAME.png ...] [--min-std 0.02] [--allow-empty]

Expected figures are those the plotting scripts recorded in
FIGDIR/figures.json (each script lists the PNGs it wrote on its last run,
and an empty list when it rightly had nothing to draw), plus any --expect
names, plus every other *.png found in FIGDIR. For each one:

* the PNG exists and matplotlib.image can decode it;
* it is not blank: the standard deviation of its grey levels is above
  --min-std (a white page has 0; a plot with axes and text is well above
  0.05), and it is not mostly a single flat colour;
* its PDF twin exists and starts with the PDF signature.

One line per figure, then "N passed, M failed" alone on the last line; the
exit status is 1 when anything failed or when no figure was expected at all
(an empty folder is more likely a broken pipeline than a success; pass
--allow-empty when the scripts may rightly draw nothing).
"""

from __future__ import annotations

import argparse
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import numpy as np  # noqa: E402

MANIFEST = "figures.json"


def expected_figures(fig_dir: str, extra: list[str]) -> tuple[list[str], list[str]]:
    """(names to check, problems with the manifest itself)."""
    names: set[str] = set(extra)
    problems = []
    path = os.path.join(fig_dir, MANIFEST)
    if os.path.exists(path):
        try:
            with open(path, encoding="utf-8") as fh:
                manifest = json.load(fh)
            for pngs in manifest.values():
                names.update(pngs)
        except (OSError, ValueError) as exc:
            problems.append(f"{MANIFEST}: unreadable ({exc})")
    if os.path.isdir(fig_dir):
        names.update(f for f in os.listdir(fig_dir) if f.lower().endswith(".png") and not f.startswith("."))
    return sorted(names), problems


def check_png(path: str, min_std: float) -> str | None:
    """None when the image is fine, otherwise the reason it is not."""
    if not os.path.isfile(path):
        return "missing"
    try:
        img = mpimg.imread(path)
    except Exception as exc:  # any decoding failure means a broken file
        return f"not a readable image ({exc})"
    img = np.asarray(img, dtype=float)
    if img.ndim not in (2, 3) or img.shape[0] < 10 or img.shape[1] < 10:
        return f"implausible image shape {img.shape}"
    if img.max() > 1.0:  # integer PNGs decode to 0..255 on some backends
        img = img / 255.0
    grey = img if img.ndim == 2 else img[..., :3].mean(axis=2)
    std = float(grey.std())
    if std < min_std:
        return f"blank (grey-level std {std:.4f} < {min_std})"
    # A figure whose axes were drawn but whose data were not is still mostly
    # background; a figure that is *all* one colour besides a few pixels is
    # suspect too. Require some share of non-background pixels.
    background = np.median(grey)
    ink = float(np.mean(np.abs(grey - background) > 0.1))
    if ink < 0.005:
        return f"nearly empty ({ink:.2%} of pixels differ from the background)"
    return None


def check_pdf(path: str) -> str | None:
    if not os.path.isfile(path):
        return "PDF twin missing"
    with open(path, "rb") as fh:
        head = fh.read(5)
    if head != b"%PDF-":
        return "PDF twin is not a PDF"
    if os.path.getsize(path) < 1000:
        return "PDF twin suspiciously small"
    return None


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("figdir", help="folder with the figures")
    ap.add_argument("--expect", nargs="*", default=[], metavar="NAME.png", help="figures that must exist")
    ap.add_argument("--allow-empty", action="store_true",
                    help="pass when the scripts rightly drew nothing (default: that fails)")
    ap.add_argument("--min-std", type=float, default=0.02, help="blank threshold on grey-level std (0..1)")
    args = ap.parse_args()

    names, problems = expected_figures(args.figdir, args.expect)
    passed, failed = 0, len(problems)
    for p in problems:
        print(f"FAIL {p}")
    if not names and not args.allow_empty:
        print(f"FAIL no figures found or expected in {args.figdir} (use --allow-empty if that is right)")
        failed += 1
    for name in names:
        png = os.path.join(args.figdir, name)
        reason = check_png(png, args.min_std) or check_pdf(os.path.splitext(png)[0] + ".pdf")
        if reason:
            failed += 1
            print(f"FAIL {name}: {reason}")
        else:
            passed += 1
            print(f"ok   {name}")
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
