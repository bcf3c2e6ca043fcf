#!/usr/bin/env python3
"""Compares two snapshot directories (scripts/dev/snapshot.sh) byte for byte, except wall-clock
times: CSV columns of times (TIMED) are dropped, and the gnuplot inputs and plots
and report tables that carry those times are compared through their CSVs only."""
import csv, filecmp, os, sys

a, b = sys.argv[1], sys.argv[2]
# Columns measured in wall-clock time, or fitted to it (premise's fits of tests and kinds to
# time, sorting's per-test times).
TIMED = ("seconds", "us_per_ray", "us_sorted", "us_stored", "ns_per_test", "overhead_pct",
         "time_", "fit_", "err_tests", "err_kinds")
bad = []
fa = sorted(os.path.relpath(os.path.join(r, f), a) for r, _, fs in os.walk(a) for f in fs)
fb = sorted(os.path.relpath(os.path.join(r, f), b) for r, _, fs in os.walk(b) for f in fs)
if fa != fb:
    bad.append(f"file lists differ: {sorted(set(fa) ^ set(fb))}")
timed_stems = set()
for rel in fa:
    if rel.endswith(".csv"):
        head = open(os.path.join(a, rel)).readline()
        if any(t in head for t in TIMED):
            timed_stems.add(rel[:-4])
same = 0
for rel in sorted(set(fa) & set(fb)):
    pa, pb = os.path.join(a, rel), os.path.join(b, rel)
    stem, ext = os.path.splitext(rel)
    if ext == ".csv" and stem in timed_stems:
        ra, rb = list(csv.reader(open(pa))), list(csv.reader(open(pb)))
        keep = [i for i, h in enumerate(ra[0]) if not any(t in h for t in TIMED)]
        if [[r[i] for i in keep] for r in ra] != [[r[i] for i in keep] for r in rb]:
            bad.append(rel)
        else:
            same += 1
        continue
    if stem in timed_stems or rel.endswith("report.filtered"):
        continue  # timings inside; their numbers are checked through the CSVs / stats files
    if filecmp.cmp(pa, pb, shallow=False):
        same += 1
    else:
        bad.append(rel)
for x in bad:
    print("DIFFERS:", x)
print(f"{same} files identical, {len(bad)} differ")
sys.exit(1 if bad else 0)
