#!/usr/bin/env python3
"""Compares two `sunlit district` runs, and tiles' peak memory against a whole run's
(docs/district.md, "2,000 buildings on Slurm's tiles"). A benchmark tool, not shipped code.

    scripts/compare-district.py rows DIR_A DIR_B
        Every row of DIR_A's tile records (`.done/tile-*.json`, full f64) against DIR_B's, matched by
        surface name: row counts, names present in only one, and per column the largest |A - B|
        with its surface. Exits 1 when the names differ or any |A - B| exceeds --tolerance
        (default 1e-9).

    scripts/compare-district.py peaks WHOLE_TIME TILE_TIME...
        GNU `/usr/bin/time -v` outputs (files): each tile's "Maximum resident set size" as a share
        of the whole run's, the largest first. Exits 1 when a tile's share exceeds --limit
        (default 0.40, the issue's target).
"""

import argparse
import glob
import json
import os
import re
import sys

COLUMNS = ["area", "direct", "sky_diffuse", "ground_reflected", "total", "sun_hours", "mean_fraction"]


def rows_of(folder):
    """{surface: row} over every tile record of a run's folder."""
    rows = {}
    records = sorted(glob.glob(os.path.join(folder, ".done", "tile-*.json")))
    if not records:
        sys.exit(f"{folder}: no tile records in .done/")
    for path in records:
        with open(path) as f:
            record = json.load(f)
        for row in record["rows"]:
            if row["surface"] in rows:
                sys.exit(f"{path}: surface {row['surface']} is in two tiles")
            rows[row["surface"]] = row
    return rows, len(records)


def compare_rows(args):
    a, tiles_a = rows_of(args.a)
    b, tiles_b = rows_of(args.b)
    print(f"A {args.a}: {len(a)} rows in {tiles_a} tile record(s)")
    print(f"B {args.b}: {len(b)} rows in {tiles_b} tile record(s)")
    only_a, only_b = sorted(set(a) - set(b)), sorted(set(b) - set(a))
    for name, only in (("A", only_a), ("B", only_b)):
        if only:
            print(f"only in {name}: {len(only)} rows, e.g. {only[:5]}")
    worst = 0.0
    common = sorted(set(a) & set(b))
    for column in COLUMNS:
        largest, where = max(((abs(a[n][column] - b[n][column]), n) for n in common), default=(0.0, None))
        worst = max(worst, largest)
        print(f"{column:17s} max |A-B| {largest:.3e}  ({where})")
    identical = sum(all(a[n][c] == b[n][c] for c in COLUMNS) for n in common)
    print(f"rows compared: {len(common)}; identical to the last bit: {identical}; worst |A-B| over every column: {worst:.3e}")
    failed = bool(only_a or only_b) or worst > args.tolerance
    print("FAIL" if failed else f"OK: every value within {args.tolerance:g}")
    return 1 if failed else 0


def peak_kib(path):
    """The 'Maximum resident set size (kbytes)' of a GNU time -v output."""
    with open(path) as f:
        text = f.read()
    found = re.search(r"Maximum resident set size \(kbytes\): (\d+)", text)
    if not found:
        sys.exit(f"{path}: no 'Maximum resident set size' line (not GNU time -v output?)")
    return int(found.group(1))


def compare_peaks(args):
    whole = peak_kib(args.whole)
    tiles = sorted(((peak_kib(p), p) for p in args.tiles), reverse=True)
    print(f"whole run: {whole / 1024:.1f} MiB ({whole} kB)  {args.whole}")
    for kib, path in tiles:
        print(f"{kib / 1024:8.1f} MiB  {100 * kib / whole:5.1f} %  {path}")
    largest = tiles[0][0]
    median = tiles[len(tiles) // 2][0]
    print(f"tiles: largest {largest / 1024:.1f} MiB = {100 * largest / whole:.1f} % of the whole run's; "
          f"median {median / 1024:.1f} MiB = {100 * median / whole:.1f} %")
    failed = largest > args.limit * whole
    print("FAIL" if failed else f"OK: every tile within {100 * args.limit:g} %")
    return 1 if failed else 0


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    rows = sub.add_parser("rows", help="every row of two runs' tile records")
    rows.add_argument("a")
    rows.add_argument("b")
    rows.add_argument("--tolerance", type=float, default=1e-9)
    peaks = sub.add_parser("peaks", help="tiles' peak memory against the whole run's")
    peaks.add_argument("whole")
    peaks.add_argument("tiles", nargs="+")
    peaks.add_argument("--limit", type=float, default=0.40)
    args = parser.parse_args()
    sys.exit(compare_rows(args) if args.command == "rows" else compare_peaks(args))


if __name__ == "__main__":
    main()
