"""Identify the inertia model and the friction together from a walk's torques, then estimate again with it.

    python examples/identify_inertia.py

The thesis traced its unphysical real-robot friction to an inaccurate inertia model (ch. 7) and proposed
identifying the model from the same logs (ch. 8). Here a walk is simulated with TALOS's URDF and Table 6.1
friction, but seen through a wrong model (every body's principal moments +10 %, masses +5 %): the
acceleration route's friction is off; the identified model predicts held-out torques far better and its
friction is close to the truth. The corrected URDF is written.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import wbfriction
from wbfriction.fit.targets import THESIS_TARGETS, friction_by_group
from wbfriction.inertia import identification_of, identify, scaled_robot, write_urdf
from wbfriction.sim import IdealOptions, simulate_ideal
from wbfriction.walking import GaitOptions, walking_reference


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=2, help="steps per direction of the combined walk")
    args = parser.parse_args()
    true_robot = wbfriction.load_robot("talos")
    friction = friction_by_group(true_robot.groups, THESIS_TARGETS)
    reference = walking_reference(true_robot, GaitOptions(gait="combined", steps=args.steps))
    log = simulate_ideal(true_robot, reference, friction, IdealOptions(substeps=10)).log

    wrong = scaled_robot(scaled_robot(true_robot, 1.1, "rotational"), 1.05, "mass")
    loop = identify(wrong, log, stribeck=0.2, passes=1)  # v_s held at 0.2 rad/s: one identification
    final = loop.final
    result = identification_of(loop)  # the typed result: what `wbfriction identify --json` writes
    knee = "leg_right_4_joint"
    h = result.joints[knee].holdout_rms
    print(f"held-out torque RMS of the right knee [N·m]: given model {h.given:.3f}, "
          f"given + its best friction {h.given_with_friction:.3f}, identified {h.identified:.4f}")
    print(f"total mass [kg]: true {sum(b.mass for b in true_robot.model.inertias):.2f}, given "
          f"{sum(b.mass_given for b in result.bodies):.2f}, identified {sum(b.mass for b in result.bodies):.2f}")
    for label, fit in (("given model", result.joints[knee].acceleration_route_given_model),
                       ("identified model", result.joints[knee].acceleration_route)):
        p = fit.params
        print(f"right knee friction through the {label}: F_v {p.F_v:.3f}, F_c {p.F_c:.3f}, tau_os {p.tau_os:.3f} "
              f"(true {friction[knee].F_v}, {friction[knee].F_c}, {friction[knee].tau_os}; {fit.verdict().status})")
    out = Path(tempfile.mkdtemp(prefix="wbfriction-identify-")) / "identified.urdf"
    write_urdf(wrong, final.identification.pi, out)
    print(f"wrote {out} (estimate with it: wbfriction estimate LOG --robot talos --urdf {out})")


if __name__ == "__main__":
    main()
