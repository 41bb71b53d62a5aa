"""Every default picked by looking at data, picked again across every real dataset and the simulators (issue 52).

Runs :func:`wbfriction.studies.defaults.run_study`: each default (the identification's link margin and prior
tolerance, the estimate's noise target, the fit's selection tolerance and terms, the statuses' thresholds) set to
each of a few values, the others at their defaults, on the KUKA LWR4+, the UR10e and the Panda (their routes, scored
against the peer's held-out error or the published curve) and on the arm simulator, the ideal and the MuJoCo
simulators (scored against the injected friction); then, per default, the value chosen over all of them and, per
dataset, the value chosen without it (leave one dataset out). Its tables are the README's *Defaults chosen across the
data*. About an hour on two cores (the identifications dominate).

    python benchmarks/study_defaults.py [--knobs link_margin,terms] [--cases kuka-lwr4,ur10e] [-o DIR]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

from wbfriction.datasets import DATA_ENV
from wbfriction.studies.default_cases import CASES
from wbfriction.studies.defaults import KNOBS, as_json, markdown, run_study

REPO = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--knobs", default=",".join(k.name for k in KNOBS))
    parser.add_argument("--cases", default=",".join(c.name for c in CASES))
    parser.add_argument("-o", "--output", type=Path, default=Path("study_defaults"),
                        help="folder for the logs and defaults.json / defaults.md")
    args = parser.parse_args()
    os.environ.setdefault(DATA_ENV, str(REPO.parent / "shared" / "real-data"))
    knobs = [k for k in KNOBS if k.name in args.knobs.split(",")]
    cases = [c for c in CASES if c.name in args.cases.split(",")]
    if not knobs or not cases:
        sys.exit(f"--knobs of {', '.join(k.name for k in KNOBS)}; --cases of {', '.join(c.name for c in CASES)}")
    start = time.perf_counter()
    choices = run_study(args.output, knobs, cases, say=lambda s: print(f"[{time.perf_counter() - start:6.0f} s] {s}",
                                                                      flush=True))
    text = markdown(choices)
    (args.output / "defaults.md").write_text(text)
    (args.output / "defaults.json").write_text(json.dumps(as_json(choices), indent=1, default=str))
    print()
    print(text)
    print(f"study took {time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()
