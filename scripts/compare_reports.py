#!/usr/bin/env python3
"""Hold two sets of diagnosis reports against each other, report by report.

    python3 scripts/compare_reports.py BEFORE_DIR AFTER_DIR

A change meant to move code and not behaviour must give the same reports: the same JSON,
byte for byte once timings are left out. Each folder holds `NAME.json` reports, as the
diagnosis's end-to-end cases write them with `JETPIPE_CASE_REPORTS=DIR` or as
`jetpipe diagnose ... --out DIR` writes them. Keys that hold wall or CPU times (any key
whose name contains `seconds_wall`, `wall_s`, `cpu_s`, `elapsed` or `timing`) are dropped
before the comparison; everything else, numbers included, must be identical.

Prints one line per report that differs, with the first differing paths, and a count.
Exits 1 when a report differs or exists on one side only, 0 otherwise.
"""

import json
import sys
from pathlib import Path

TIMING_KEYS = ("seconds_wall", "wall_s", "cpu_s", "elapsed", "timing")


def without_timings(value):
    if isinstance(value, dict):
        return {k: without_timings(v) for k, v in value.items() if not any(t in k for t in TIMING_KEYS)}
    if isinstance(value, list):
        return [without_timings(v) for v in value]
    return value


def differences(a, b, path="$", out=None, most=5):
    """The paths at which `a` and `b` differ, the first `most` of them."""
    out = [] if out is None else out
    if len(out) >= most:
        return out
    if type(a) is not type(b):
        out.append(f"{path}: {json.dumps(a)[:80]} vs {json.dumps(b)[:80]}")
    elif isinstance(a, dict):
        for key in sorted(set(a) | set(b)):
            if key not in a or key not in b:
                out.append(f"{path}.{key}: only {'after' if key in b else 'before'}")
            else:
                differences(a[key], b[key], f"{path}.{key}", out, most)
    elif isinstance(a, list):
        if len(a) != len(b):
            out.append(f"{path}: {len(a)} items vs {len(b)}")
        for i, (x, y) in enumerate(zip(a, b)):
            differences(x, y, f"{path}[{i}]", out, most)
    elif a != b:
        out.append(f"{path}: {json.dumps(a)[:80]} vs {json.dumps(b)[:80]}")
    return out[:most]


def main(argv):
    if len(argv) != 3:
        print(__doc__.strip().splitlines()[2].strip(), file=sys.stderr)
        return 2
    before_dir, after_dir = Path(argv[1]), Path(argv[2])
    for d in (before_dir, after_dir):
        if not d.is_dir():
            print(f"compare_reports: {d} is not a folder", file=sys.stderr)
            return 2
    before = {p.name: p for p in before_dir.glob("*.json")}
    after = {p.name: p for p in after_dir.glob("*.json")}
    differing = 0
    for name in sorted(set(before) | set(after)):
        if name not in after or name not in before:
            print(f"{name}: only in {'before' if name in before else 'after'}")
            differing += 1
            continue
        a = without_timings(json.loads(before[name].read_text()))
        b = without_timings(json.loads(after[name].read_text()))
        if json.dumps(a, sort_keys=True) != json.dumps(b, sort_keys=True):
            differing += 1
            print(f"{name}: differs")
            for line in differences(a, b):
                print(f"    {line}")
    total = len(set(before) | set(after))
    same = total - differing
    print(f"{same} of {total} reports identical apart from timings; {differing} differ")
    return 1 if differing else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
