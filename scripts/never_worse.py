"""Whether any diagnosis handed back a worse model than the one it started from.

    python3 scripts/never_worse.py REPORT.json...

Reads the reports `jetpipe diagnose --report` wrote and prints one sentence: on how many the
final model's force error is above the starting model's, held out and over the whole recording,
by more than a thousandth of the force's noise floor (the diagnosis's own allowance for a term
that leaves the force alone), and the largest after-minus-before in noise floors. Prints the names of the
reports where it is. The benchmark scripts append its sentence under their tables.
"""

import json
import sys

ALLOWANCE_SHARE_OF_NOISE = 1e-3


def excesses(report):
    noise = report["noise_floor_N"]
    heldout = (report["heldout"]["after_rms_N"] - report["heldout"]["before_rms_N"]) / noise
    whole = (report["after"]["force_rms_N"] - report["before"]["force_rms_N"]) / noise
    return heldout, whole


def main(paths):
    if not paths:
        print("usage: python3 scripts/never_worse.py REPORT.json...", file=sys.stderr)
        return 2
    worse_heldout, worse_whole, largest = [], [], None
    for path in paths:
        with open(path) as f:
            report = json.load(f)
        heldout, whole = excesses(report)
        name = report.get("recording", path)
        if heldout > ALLOWANCE_SHARE_OF_NOISE:
            worse_heldout.append(name)
        if whole > ALLOWANCE_SHARE_OF_NOISE:
            worse_whole.append(name)
        top = max(heldout, whole)
        largest = top if largest is None else max(largest, top)
    n = len(paths)
    sentence = (
        f"Final model's force error above the starting model's (by more than {ALLOWANCE_SHARE_OF_NOISE:g} "
        f"of the noise floor): held out on {len(worse_heldout)} of {n} reports, over the whole recording "
        f"on {len(worse_whole)} of {n}; after minus before is at most {largest:+.3f} noise floors"
    )
    worse = sorted(set(worse_heldout) | set(worse_whole))
    print(sentence + (f" ({', '.join(worse)})." if worse else "."))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
