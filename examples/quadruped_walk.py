"""A quadruped on point feet: which joints each contact pattern determines, and their friction where it is.

    python examples/quadruped_walk.py                     # a walk of the built-in go2_walking, ideal simulator
    python examples/quadruped_walk.py --foot-forces 3d    # the feet's forces logged: the stance legs too

Three feet are down while one leg swings. Without the feet's forces only the swinging leg's friction is determined
(three feet can push against each other without any wrench on the base); with them, every joint's. Sign convention:
``tau_f`` is the torque friction exerts on the joint; the model f(qd) is fitted to ``-tau_f``.
"""

from __future__ import annotations

import argparse

import numpy as np

import wbfriction
from wbfriction.fit.joints import fit_estimate
from wbfriction.fit.options import FitOptions
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.options import EstimateOptions
from wbfriction.friction.point_contacts import determined_shares
from wbfriction.sim.quadruped import QuadrupedOptions, simulate_quadruped
from wbfriction.walking.quadruped import GaitOptions, quadruped_reference


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--foot-forces", choices=("none", "normal", "3d"), default="none")
    parser.add_argument("--duration", type=float, default=4.0, help="simulated time [s]")
    args = parser.parse_args()

    robot = wbfriction.load_robot("go2_walking")
    reference = quadruped_reference(robot, GaitOptions(gait="walk", duration=args.duration))
    run = simulate_quadruped(robot, reference, QuadrupedOptions(foot_forces=args.foot_forces))
    # the simulator's true derivatives and base motion: the determined friction is then exact
    est = estimate_log(robot, run.log, EstimateOptions(diff="true", route="acceleration", base_motion="logged",
                                                       check_route=False))
    shares = determined_shares(est)
    assert shares is not None  # a robot on point feet
    for pattern, n, share in zip(shares.patterns, shares.samples, shares.share):
        legs = sorted({j[:2] for j, s in zip(shares.joints, share) if s == 1.0})
        print(f"{pattern} ({n} samples): determined {', '.join(legs) or 'none'}")
    fits = fit_estimate(est, FitOptions(model="thesis"), fixed={"S": 0.0, "v_s": 0.1})
    for fit in fits:
        errors = fit.error_percent() or {}
        print(f"{fit.joint}: {fit.verdict().status}, F_c {fit.params.F_c:.3f} N·m ({errors.get('F_c', np.nan):.1f} % "
              f"off), F_v {fit.params.F_v:.3f} N·m·s/rad ({errors.get('F_v', np.nan):.1f} % off)")


if __name__ == "__main__":
    main()
