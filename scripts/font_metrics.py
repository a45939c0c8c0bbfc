"""Prints src/report/figures/metrics.rs: the advance width of every character of a font (the
embedded DejaVu Sans subset), for the figure layout. Usage: font_metrics.py FONT.ttf"""
import sys
from fontTools.ttLib import TTFont

font = TTFont(sys.argv[1])
upm = font["head"].unitsPerEm
hhea = font["hhea"]
hmtx = font["hmtx"]
rows = sorted((cp, hmtx[g][0]) for cp, g in font.getBestCmap().items())
print("//! Advance widths of the embedded font (DejaVu Sans, the subset in assets/fonts/), made by")
print("//! scripts/font_metrics.py from that file: do not edit by hand.")
print()
print(f"/// Font units per em.\npub(crate) const UNITS_PER_EM: f64 = {upm}.0;")
print(f"/// Ascender, font units.\npub(crate) const ASCENT: f64 = {hhea.ascent}.0;")
print(f"/// Descender (negative), font units.\npub(crate) const DESCENT: f64 = {hhea.descent}.0;")
print("/// (code point, advance width in font units), sorted by code point.")
print(f"pub(crate) const ADVANCE: [(u32, u16); {len(rows)}] = [")
line = "   "
for cp, adv in rows:
    item = f" (0x{cp:04X}, {adv}),"
    if len(line) + len(item) > 96:
        print(line)
        line = "   "
    line += item
print(line)
print("];")
