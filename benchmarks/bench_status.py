"""Whether a status holds against the truth, on the simulators and the real sets (issue 63, item 7).

Each simulated case (:data:`wbfriction.studies.status.CASES`: the crawl on point feet with and without 3-D foot
forces and with sensor noise, the noisy Panda, the README's TALOS walk, the hung Go2 with moving, still and 80 ms late
set-points) runs the route the docs give a user, with defaults, each command its own process; what the route wrote is
scored against the truth the simulator put in the log: per case how many fits are ``ok`` and good, ``ok`` and bad,
not ``ok`` and good, not ``ok`` and bad (good: F_c and F_v within 5 % of the truth noise-free, 10 % noisy), the
coverage of ±2 standard errors, the standard errors below their Cramér-Rao bound, then a line per case with the
issue's targets. Every real set then runs through its route as ``bench_real.py`` runs it: its ``ok`` count beside
that benchmark's columns. About 12 minutes on two cores, the same seeds always.

    python benchmarks/bench_status.py [--cases crawl,pd-late] [--datasets kuka-lwr4] [--keep DIR] [-o DIR]

``--datasets none`` skips the real sets; ``-o DIR`` writes ``status.md`` and ``status.json`` there.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from wbfriction.datasets import DATA_ENV, DATASETS
from wbfriction.studies.status import CASES, cases_markdown, real_markdown, results_json, run_case, run_real

REPO = Path(__file__).resolve().parents[1]
NAMES = tuple(c.name for c in CASES)


def chosen(text: str, known: tuple[str, ...], option: str) -> list[str]:
    """The comma-separated names of ``text`` (``all``: every one, ``none``: none), each one of ``known``."""
    if text == "none":
        return []
    names = list(known) if text == "all" else [n.strip() for n in text.split(",") if n.strip()]
    unknown = [n for n in names if n not in known]
    if unknown:
        sys.exit(f"{option}: unknown {', '.join(unknown)} (one of {', '.join(known)}, all or none)")
    return names


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default="all", help="comma-separated, of " + ", ".join(NAMES) + " (or none)")
    parser.add_argument("--datasets", default="all", help="comma-separated, of " + ", ".join(DATASETS) + " (or none)")
    parser.add_argument("--keep", type=Path, help="run in this folder and keep what the commands wrote")
    parser.add_argument("-o", "--output", type=Path, help="write status.md and status.json into this folder")
    args = parser.parse_args()
    cases = [c for c in CASES if c.name in chosen(args.cases, NAMES, "--cases")]
    datasets = chosen(args.datasets, tuple(DATASETS), "--datasets")
    if args.output is not None and not args.output.is_dir():
        sys.exit(f"-o: {args.output}: no such folder")
    os.environ.setdefault(DATA_ENV, str(REPO.parent / "shared" / "real-data"))
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="bench_status-") as scratch:
        base = args.keep or Path(scratch)
        scores, real = [], []
        for case in cases:
            print(f"{case.name}: {case.what}", flush=True)
            scores.append(run_case(case, base / case.name, echo=lambda line: print(f"  {line}", flush=True)))
        for name in datasets:
            print(f"{name}:", flush=True)
            real.append(run_real(name, base / name, echo=lambda line: print(f"  {line}", flush=True)))
    text = "\n\n".join(t for t in (cases_markdown(scores) if scores else "", real_markdown(real) if real else "") if t)
    print()
    print(text)
    print(f"\n{time.perf_counter() - start:.0f} s in all")
    if args.output is not None:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=REPO, capture_output=True,
                                text=True).stdout.strip()
        (args.output / "status.md").write_text(text + "\n")
        (args.output / "status.json").write_text(results_json(scores, real, {"commit": commit}))


if __name__ == "__main__":
    main()
