"""Estimate the joint friction of a log and fit a friction model to every joint (chosen per joint on held-out data).

    python examples/estimate_a_log.py                 # simulates a short TALOS walk to have a log
    python examples/estimate_a_log.py walk.parquet    # or any log in the wbfriction format

The friction table and the parameters JSON are written beside the log. Sign convention: ``tau_f`` is the
torque friction exerts on the joint; the model f(qd) (e.g. eq. 3.5) is fitted to ``-tau_f``, so F_c, F_v > 0.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import wbfriction
from wbfriction.fit.targets import THESIS_TARGETS, friction_by_group
from wbfriction.logs import write_table
from wbfriction.sim import IdealOptions, simulate_ideal
from wbfriction.walking import GaitOptions, walking_reference


def simulated_log(robot: wbfriction.Robot, path: Path, steps: int) -> Path:
    """A walk of the ideal simulator with the thesis's Table 6.1 friction on the legs, written as a log."""
    reference = walking_reference(robot, GaitOptions(gait="combined", steps=steps))
    friction = friction_by_group(robot.groups, THESIS_TARGETS)
    result = simulate_ideal(robot, reference, friction, IdealOptions(substeps=10))
    wbfriction.write_log(result.log, robot, path)
    return path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("log", nargs="?", type=Path, help="a log (.parquet, .csv, .h5); default: simulate one")
    parser.add_argument("--steps", type=int, default=2, help="steps per direction of the simulated walk")
    args = parser.parse_args()

    robot = wbfriction.load_robot("talos")
    folder = args.log.parent if args.log else Path(tempfile.mkdtemp(prefix="wbfriction-example-"))
    path = args.log or simulated_log(robot, folder / "walk.parquet", args.steps)

    log = wbfriction.read_log(path, robot)  # validated: names, units, time stamps, contact flags
    estimate = wbfriction.estimate_log(robot, log, wbfriction.EstimateOptions(diff="central", mask="swing"))
    fits = wbfriction.fit_estimate(estimate)

    write_table(wbfriction.friction_table(estimate), folder / "friction.parquet")
    wbfriction.write_params(folder / "params.json", fits)
    legs = [j for frame in robot.contact_frames for j in robot.limb(frame)]
    print(f"{len(log)} samples, {int(estimate.unique.sum())} in single support; fitted models of the legs:")
    print(f"{'joint':20s} {'N':>6s} {'F_v':>18s} {'F_c':>18s} {'tau_os':>18s}   (value ± standard error)")
    for fit in fits:
        if fit.joint in legs and fit.params is not None:
            cells = [f"{getattr(fit.params, n):8.4f} ± {fit.stderr[n]:7.1g}" for n in ("F_v", "F_c", "tau_os")]
            print(f"{fit.joint:20s} {fit.n_samples:6d} " + " ".join(cells))
    print(f"wrote {folder / 'friction.parquet'} and {folder / 'params.json'}")


if __name__ == "__main__":
    main()
