"""Every real dataset through the route the README gives a user, against its published reference (issue 52).

Run it after any change that can move a number, and put its table in the note. For each dataset (``wbfriction
dataset NAME``; offline, ``WBFRICTION_DATA`` names the local copy, default ``../shared/real-data`` beside the
checkout), the commands the dataset prints run as a user runs them (each its own process, timed), then per joint:

* ``status``: the fit's;
* ``curve``: the odd part's relative RMS error against the published curve over ``|qd| >= 0.1`` rad/s (UR10e:
  Mamedov et al.'s Coulomb-viscous; Panda: Gaz et al.'s sigmoid), and ``sigmas``: that deviation in the fit's own
  standard errors (honest errors put it within 3);
* ``held-out``: the torque RMS on the held-out log (KUKA: run 3; UR10e: the shoulder pan's sweep, the other joints
  at rest there, marked ``still``; Aliengo, Go2: the last 40 %), and ``peer``: FloBaRoID's method on run 3 (KUKA),
  the iit-DLSLab's PACE-style parameters through the same estimate (Aliengo, Go2); for a PD-driven robot, the
  held-out set-points replayed in MuJoCo, the joints' tracking error with ours and with the peer's parameters; and
  the held-out torque through the same route with the robot TOML as given (the identified TOML must do at least as
  well on every joint) and with the route run on the whole log, as the peer was fitted.

Then one line per dataset with the issue's targets: UR10e every joint within 5 %; Panda every ``ok`` joint within
15 % and 3 standard errors; KUKA and Aliengo every joint better than the peer (the Go2 is scored the same way).

    python benchmarks/bench_real.py [--datasets kuka-lwr4,ur10e,panda,aliengo,go2] [--keep DIR]
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
from pathlib import Path

from wbfriction.datasets import DATA_ENV, DATASETS
from wbfriction.studies.real_data import DatasetRun, run_dataset, summarise

REPO = Path(__file__).resolve().parents[1]
TARGET_ERROR = {"ur10e": 0.05, "panda": 0.15}
"""The issue's curve targets: every joint (UR10e), every ``ok`` joint (Panda) within this share."""


def cell(x: float, fmt: str) -> str:
    return "–" if not math.isfinite(x) else format(x, fmt)


def table(runs: list[DatasetRun]) -> str:
    """The markdown table of every joint of ``runs``."""
    lines = ["| dataset | joint | status | model | curve [%] | sigmas | held-out [N·m] | peer [N·m] |",
             "|---|---|---|---|---|---|---|---|"]
    for run in runs:
        if run.failed:
            lines.append(f"| {run.name} | (failed) | {run.failed} | | | | | |")
        for j in run.joints:
            held = cell(j.held_out, ".3f") + ("" if j.held_out_moved or not math.isfinite(j.held_out) else " still")
            lines.append(f"| {run.name} | {j.joint} | {j.status} | {j.model} | {cell(100 * j.curve_error, '.1f')} | "
                         f"{cell(j.curve_sigmas, '.1f')} | {held} | {cell(j.peer, '.3f')} |")
    return "\n".join(lines)


ROLLOUTS = (("rollout", "rollout, ours"), ("refined_rollout", "refined"), ("peer_rollout", "rollout, peer"),
            ("whole_rollout", "refined on the whole log (the peer's footing)"))


def rollouts(runs: list[DatasetRun]) -> str:
    """The PD-driven robots' held-out rollouts: each joint's tracking error, ours (the route's export and its
    refinement), the peer's, and the export refined on the whole log as the peer was fitted [mrad]; the means, and
    on how many joints each of ours is at most the peer's."""
    lines = ["| dataset | joint | " + " | ".join(f"{title} [mrad]" for _, title in ROLLOUTS) + " |",
             "|---|---|" + "---|" * len(ROLLOUTS)]
    rows = [(run.name, j) for run in runs for j in run.joints if math.isfinite(j.rollout)]
    lines += [f"| {name} | {j.joint} | " + " | ".join(cell(1e3 * getattr(j, k), ".1f") for k, _ in ROLLOUTS) + " |"
              for name, j in rows]
    for run in runs:
        scored = [j for j in run.joints if math.isfinite(j.rollout)]
        if scored:
            mean = [1e3 * sum(getattr(j, k) for j in scored) / len(scored) for k, _ in ROLLOUTS]
            lines.append(f"| {run.name} | mean | " + " | ".join(cell(m, ".2f") for m in mean) + " |")
            better = [sum(getattr(j, k) <= j.peer_rollout for j in scored) if math.isfinite(m) else None
                      for (k, _), m in zip(ROLLOUTS, mean)]
            lines.append(f"| {run.name} | at most the peer's | " + " | ".join(
                "-" if k == "peer_rollout" or b is None else f"{b} of {len(scored)}"
                for (k, _), b in zip(ROLLOUTS, better)) + " |")
    return "\n".join(lines) if rows else ""


HELD_OUT = (("held_out", "ours"), ("given_held_out", "the given TOML"),
            ("whole_held_out", "ours, on the whole log (the peer's footing)"), ("peer", "peer"))


def pd_held_out(runs: list[DatasetRun]) -> str:
    """The PD-driven robots' held-out torque RMS [N·m]: the route's (identified TOML), the same route with the TOML as
    given, the route run on the whole log as the peer was fitted, and the peer's; the means, on how many joints the
    identified TOML is at most the given one's, and on how many the whole log's is at most the peer's."""
    rows = [(run.name, j) for run in runs for j in run.joints if math.isfinite(j.given_held_out)]
    if not rows:
        return ""
    lines = ["| dataset | joint | " + " | ".join(f"{title} [N·m]" for _, title in HELD_OUT) + " |",
             "|---|---|" + "---|" * len(HELD_OUT)]
    lines += [f"| {name} | {j.joint} | " + " | ".join(cell(getattr(j, k), ".3f") for k, _ in HELD_OUT) + " |"
              for name, j in rows]
    for run in runs:
        scored = [j for j in run.joints if math.isfinite(j.given_held_out)]
        if scored:
            mean = [sum(getattr(j, k) for j in scored) / len(scored) for k, _ in HELD_OUT]
            lines.append(f"| {run.name} | mean | " + " | ".join(cell(m, ".3f") for m in mean) + " |")
            given = sum(j.held_out <= j.given_held_out for j in scored)
            peer = sum(j.whole_held_out <= j.peer for j in scored)
            lines.append(f"| {run.name} | ours at most the given TOML's; whole log at most the peer's | "
                         f"{given} of {len(scored)} | | {peer} of {len(scored)} | |")
    return "\n".join(lines)


def summary(runs: list[DatasetRun]) -> str:
    lines = ["| dataset | ok | ok within target | ok within 3 SE | worst curve | better than peer | time [s] |",
             "|---|---|---|---|---|---|---|"]
    for run in runs:
        s = summarise(run, TARGET_ERROR.get(run.name, math.inf))
        target = f"{s.ok_within_error} ({100 * TARGET_ERROR[run.name]:.0f} %)" if run.name in TARGET_ERROR else "–"
        sigmas = str(s.ok_within_3_sigmas) if run.name in TARGET_ERROR else "–"
        peer = f"{s.better_than_peer} of {s.peers}" if s.peers else "–"
        lines.append(f"| {run.name} | {s.ok} of {s.joints} | {target} | {sigmas} | "
                     f"{cell(100 * s.worst_error, '.1f')} % | {peer} | {s.seconds:.0f} |")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--datasets", default=",".join(DATASETS), help="comma-separated, of " + ", ".join(DATASETS))
    parser.add_argument("--keep", type=Path, help="run in this folder and keep what the commands wrote")
    args = parser.parse_args()
    os.environ.setdefault(DATA_ENV, str(REPO.parent / "shared" / "real-data"))
    names = [n.strip() for n in args.datasets.split(",") if n.strip()]
    unknown = [n for n in names if n not in DATASETS]
    if unknown:
        sys.exit(f"--datasets: unknown {', '.join(unknown)} (one of {', '.join(DATASETS)})")
    with tempfile.TemporaryDirectory(prefix="bench_real-") as scratch:
        base = args.keep or Path(scratch)
        runs = []
        for name in names:
            print(f"{name}:", flush=True)
            runs.append(run_dataset(name, base / name, echo=lambda line: print(f"  {line}", flush=True)))
    print()
    print(table(runs))
    print()
    print(summary(runs))
    for extra in (pd_held_out(runs), rollouts(runs)):
        if extra:
            print()
            print(extra)


if __name__ == "__main__":
    main()
