"""The randomised generalisation benchmark: scenarios drawn from seeds, each a MuJoCo-simulated log with a known
truth, run through the documented route and scored on what the route wrote (:mod:`wbfriction.studies.generalise`).

Seeds ``--first`` to ``--first + --seeds - 1`` are drawn (:func:`~wbfriction.studies.generalise.scenario.draw`:
fixed-base arms, the Panda and random serial chains, on MuJoCo with any of seven friction laws; the hung PD-driven
Go2; the Go2 crawling on point feet; TALOS walking); those of the chosen set (``--set``: ``test`` by default, the
numbers every decision is judged on; ``tuning`` the ones rules may be chosen on;
:func:`~wbfriction.studies.generalise.scenario.split`) and classes (``--classes``) run, one Dask task each on a
local cluster of ``--workers`` single-threaded processes (each task simulates its scenario and runs the route's
commands as processes). Printed, per class and overall: the four counts of fits (good: F_c and F_v within 10 % of
the truth), the coverage of ±2 standard errors (of F_c and F_v, the issue's target; and of every value, a PD-driven
robot's armatures, offsets and delay too), the ``ok`` values outside ±20 % of the truth; for the hung PD-driven
robots what ``identify --actuator pd --config-output`` wrote against the given TOML; then the counts per law, per
excitation and per robot. The default (300 seeds, the test set: about 145 scenarios) takes about 30 minutes on two
cores.

    python benchmarks/bench_generalise.py [--seeds 300] [--set test|tuning|all] [--classes arm,pd,crawl,humanoid]
        [--workers 2] [--first 0] [--keep DIR [--score-only]] [-o DIR]

``-o DIR`` writes ``generalise.md`` and ``generalise.json`` there; ``--keep DIR`` keeps each scenario's folder;
``--score-only`` scores the folders a run kept there again (a change of the scoring, not of the tool), in seconds.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from wbfriction.studies.generalise.scenario import CLASSES, SETS, draw, split
from wbfriction.studies.generalise.score import (
    ScenarioScore,
    breakdown,
    markdown,
    run_scenario,
    score_scenario,
    summaries,
)
from wbfriction.studies.status import GOOD_NOISY, CaseScore

REPO = Path(__file__).resolve().parents[1]


def chosen_seeds(first: int, count: int, which: str, classes: list[str]) -> list[int]:
    """The seeds of ``[first, first + count)`` in set ``which`` (or ``all``) whose class is one of ``classes``."""
    return [s for s in range(first, first + count)
            if (which == "all" or split(s) == which) and draw(s).robot_class in classes]


def _task(seed: int, base: str) -> ScenarioScore:
    """One scenario in ``base/<seed>`` (a Dask task); a defect of the generator's (any exception
    :func:`~wbfriction.studies.generalise.score.run_scenario` does not turn into a failed score) fails that scenario,
    named, not the draw."""
    try:
        return run_scenario(seed, Path(base) / str(seed))
    except Exception as exc:  # noqa: BLE001 - one scenario's defect, reported in its row
        sc = draw(seed)
        return ScenarioScore(seed, sc.set, sc.robot_class, sc.robot, sc.law, sc.excitation,
                             CaseScore(sc.name, GOOD_NOISY, failed=f"{type(exc).__name__}: {exc}"))


def rescore(seed: int, folder: Path) -> ScenarioScore:
    """``seed``'s scenario scored on the files a run kept in ``folder`` (its route not run again); a folder without
    them: failed, named."""
    sc = draw(seed)
    try:
        return score_scenario(sc, folder)
    except (ValueError, OSError, KeyError) as exc:
        return ScenarioScore(seed, sc.set, sc.robot_class, sc.robot, sc.law, sc.excitation,
                             CaseScore(sc.name, GOOD_NOISY, failed=f"{folder}: {type(exc).__name__}: {exc}"))


def run(seeds: list[int], base: Path, workers: int) -> list[ScenarioScore]:
    """Every seed's scenario on a local Dask cluster of ``workers`` processes, in seed order; printed as each
    completes."""
    from distributed import Client, as_completed

    from wbfriction.fleet.batch import local_cluster, quiet_dask_logs

    quiet_dask_logs()
    scores = {}
    with local_cluster(workers) as cluster, Client(cluster) as client:
        futures = [client.submit(_task, s, str(base), key=f"scenario-{s}", pure=False) for s in seeds]
        for i, future in enumerate(as_completed(futures), 1):
            score = future.result()
            scores[score.seed] = score
            c = score.case
            what = (f"failed: {c.failed}" if c.failed else
                    f"ok good {c.ok_good}, ok bad {c.ok_bad}, not ok good {c.not_ok_good}, not ok bad {c.not_ok_bad},"
                    f" covered {c.covered} of {c.scored}")
            print(f"[{i}/{len(seeds)}] {c.case} ({c.seconds:.0f} s): {what}", flush=True)
    return [scores[s] for s in seeds]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=300, help="how many seeds to draw (default 300)")
    parser.add_argument("--first", type=int, default=0, help="the first seed (default 0)")
    parser.add_argument("--set", default="test", choices=(*SETS, "all"), help="the seeds' set (default test)")
    parser.add_argument("--classes", default=",".join(CLASSES), help="comma-separated, of " + ", ".join(CLASSES))
    parser.add_argument("--workers", type=int, default=2, help="Dask worker processes (default 2)")
    parser.add_argument("--keep", type=Path, help="run in this folder and keep each scenario's files")
    parser.add_argument("--score-only", action="store_true",
                        help="score the scenarios' files a run kept in --keep again, without running them")
    parser.add_argument("-o", "--output", type=Path, help="write generalise.md and generalise.json into this folder")
    args = parser.parse_args()
    classes = [c.strip() for c in args.classes.split(",") if c.strip()]
    unknown = [c for c in classes if c not in CLASSES]
    if unknown:
        sys.exit(f"--classes: unknown {', '.join(unknown)} (one of {', '.join(CLASSES)})")
    if args.output is not None and not args.output.is_dir():
        sys.exit(f"-o: {args.output}: no such folder")
    seeds = chosen_seeds(args.first, args.seeds, args.set, classes)
    print(f"{len(seeds)} scenarios: seeds {args.first}-{args.first + args.seeds - 1}, set {args.set}, "
          f"classes {', '.join(classes)}, {args.workers} workers", flush=True)
    start = time.perf_counter()
    if args.score_only:
        if args.keep is None or not args.keep.is_dir():
            sys.exit("--score-only: --keep must name the folder a run kept")
        scores = [rescore(seed, args.keep / str(seed)) for seed in seeds]
    else:
        with tempfile.TemporaryDirectory(prefix="bench_generalise-") as scratch:
            base = args.keep or Path(scratch)
            base.mkdir(parents=True, exist_ok=True)
            scores = run(seeds, base, args.workers)
    wall = time.perf_counter() - start
    title = f"set {args.set}: seeds {args.first}-{args.first + args.seeds - 1}, {len(seeds)} scenarios"
    text = "\n\n".join([markdown(summaries(scores), title), breakdown(scores, "law"), breakdown(scores, "excitation"),
                        breakdown(scores, "robot")])
    text += f"\n\n{wall:.0f} s wall time on {args.workers} workers"
    print()
    print(text)
    if args.output is not None:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=REPO, capture_output=True,
                                text=True).stdout.strip()
        (args.output / "generalise.md").write_text(text + "\n")
        doc = {"commit": commit, "set": args.set, "first": args.first, "seeds": args.seeds, "wall_seconds": wall,
               "summaries": [s.__dict__ for s in summaries(scores)],
               "scenarios": [s.to_dict() for s in scores]}
        (args.output / "generalise.json").write_text(json.dumps(doc, indent=1, sort_keys=True, default=_json) + "\n")


def _json(x):
    """NaN-free JSON of what ``json`` does not know (tuples of dataclasses are dicts already)."""
    return str(x)


if __name__ == "__main__":
    main()
