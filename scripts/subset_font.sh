#!/usr/bin/env bash
# Makes assets/fonts/DejaVuSans-subset.ttf, the font the figures name first and the PNG
# renderer embeds, from Debian's fonts-dejavu-core (DejaVu Sans 2.37), and regenerates the
# advance-width table the figure layout measures text with (src/report/figures/metrics.rs).
# Needs fonttools (pip install fonttools). Run from the repository root.
set -euo pipefail
src=${1:-/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf}
pyftsubset "$src" \
  --unicodes="U+0020-007E,U+00A0-00FF,U+0300-036F,U+0370-03FF,U+2000-206F,U+2070-209F,U+2190-21FF,U+2200-22FF,U+27E8-27E9" \
  --layout-features="kern,mark,mkmk,ccmp" --no-hinting --desubroutinize \
  --name-IDs='*' --name-legacy --name-languages='*' \
  --output-file=assets/fonts/DejaVuSans-subset.ttf
python3 scripts/font_metrics.py assets/fonts/DejaVuSans-subset.ttf > src/report/figures/metrics.rs
