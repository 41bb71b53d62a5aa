"""Bring your own robot: a URDF and a TOML that names its contact frames, joint roles and groups.

    python examples/your_own_robot.py

The URDF here is TALOS's from the installed ``example-robot-data`` package (any URDF works the same way);
the TOML is written next to the outputs: the arms are declared position-controlled (their acceleration is
constrained to the measured one, thesis eq. 5.4c, their torque unknown), the knees grouped. A short walk is
simulated with friction on the knee group only, estimated and fitted with that robot description.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import wbfriction
from wbfriction.model.loading import example_robot_data_dir
from wbfriction.sim import IdealOptions, simulate_ideal
from wbfriction.walking import GaitOptions, walking_reference

ROBOT_TOML = """\
name = "my_talos"
contact_frames = ["left_sole_link", "right_sole_link"]   # 6D contacts: the soles
position_controlled = ["head_1_joint", "head_2_joint", {arms}]
# torque_controlled: every other actuated joint (the legs, the torso, the grippers)
srdf = "{srdf}"                 # optional: a standing posture to start the walk from
reference_configuration = "half_sitting"

[groups]
knee = ["leg_left_4_joint", "leg_right_4_joint"]
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=2, help="steps of the forward walk")
    parser.add_argument("-o", "--output-dir", type=Path, default=None,
                        help="where to write (default: a temporary folder)")
    args = parser.parse_args()
    out = args.output_dir or Path(tempfile.mkdtemp(prefix="wbfriction-robot-"))
    out.mkdir(parents=True, exist_ok=True)

    data = example_robot_data_dir() / "talos_data"
    arms = ", ".join(f'"arm_{side}_{i}_joint"' for side in ("left", "right") for i in range(1, 8))
    config = out / "my_talos.toml"
    config.write_text(ROBOT_TOML.format(arms=arms, srdf=data / "srdf" / "talos.srdf"))
    robot = wbfriction.load_robot(urdf=data / "robots" / "talos_reduced.urdf", config=config)
    print(f"{robot.name}: {len(robot.torque_controlled)} torque-controlled joints, "
          f"{len(robot.position_controlled)} position-controlled, contacts {', '.join(robot.contact_frames)}")

    knee = wbfriction.FrictionParams(F_v=0.3, F_c=1.2, S=0.0, v_s=0.1, tau_os=0.0, a=40.0)
    reference = walking_reference(robot, GaitOptions(gait="forward", steps=args.steps))
    result = simulate_ideal(robot, reference, {j: knee for j in robot.groups["knee"]}, IdealOptions(substeps=10))
    wbfriction.write_log(result.log, robot, out / "walk.parquet")

    estimate = wbfriction.estimate_log(robot, wbfriction.read_log(out / "walk.parquet", robot))
    for fit in wbfriction.fit_estimate(estimate):
        if fit.joint in robot.groups["knee"] and fit.params is not None:
            print(f"{fit.joint}: F_v {fit.params.F_v:.3f} (true {knee.F_v}), "
                  f"F_c {fit.params.F_c:.3f} (true {knee.F_c}), "
                  f"{fit.n_samples} swing-phase samples")
    print(f"wrote {config} and {out / 'walk.parquet'}")


if __name__ == "__main__":
    main()
