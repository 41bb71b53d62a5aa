"""A walking robot's log as its logger writes it (issue 82): the simulated twin's trot and walk, noise-free and with a
real robot's noise, through ``estimate`` and ``fit`` as a user runs them, each step against the truth
(:mod:`wbfriction.studies.walking_logs`): repeats found, contacts inferred, the base's velocity, the friction of the
swinging legs, and the same log with the simulator's contact flags and base pose given.

    python benchmarks/bench_walking_logs.py [--cases trot,walk-noisy] [--contacts soft|firm] [--keep DIR] [-o FILE.md]

``--contacts`` is the twin's MuJoCo contacts (``simulate --contacts``): ``soft`` (the default, MuJoCo's own: a stance
foot creeps about 1.5 cm/s) or ``firm`` (feet that hold).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import tempfile
import time
from pathlib import Path

from wbfriction.studies.walking_logs import CASES, markdown, score_case

NAMES = tuple(c.name for c in CASES)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default="all", help="comma-separated, of " + ", ".join(NAMES))
    parser.add_argument("--contacts", default="soft", choices=("soft", "firm"), help="the twin's MuJoCo contacts")
    parser.add_argument("--keep", type=Path, help="run in this folder and keep what the commands wrote")
    parser.add_argument("-o", "--output", type=Path, help="write the table (Markdown) to this file")
    args = parser.parse_args()
    names = NAMES if args.cases == "all" else tuple(n.strip() for n in args.cases.split(","))
    unknown = [n for n in names if n not in NAMES]
    if unknown:
        sys.exit(f"--cases: unknown {', '.join(unknown)} (one of {', '.join(NAMES)})")
    start = time.perf_counter()
    scores = []
    with tempfile.TemporaryDirectory(prefix="bench_walking-") as scratch:
        folder = args.keep or Path(scratch)
        folder.mkdir(parents=True, exist_ok=True)
        for case in (c for c in CASES if c.name in names):
            score = score_case(dataclasses.replace(case, contacts=args.contacts), folder)
            scores.append(score)
            print(f"{case.name}: done at {time.perf_counter() - start:.0f} s", file=sys.stderr)
            for joint, (status, e_c, e_v) in score.fits.items():
                given = score.given_fits.get(joint, ("-", float("nan"), float("nan")))
                print(f"  {joint:16s} raw {status:10s} F_c {e_c:6.1%} F_v {e_v:6.1%}   given {given[0]:10s} "
                      f"F_c {given[1]:6.1%} F_v {given[2]:6.1%}", file=sys.stderr)
    table = markdown(scores)
    print(table)
    print(f"\n{time.perf_counter() - start:.0f} s")
    if args.output is not None:
        args.output.write_text(table + "\n")


if __name__ == "__main__":
    main()
