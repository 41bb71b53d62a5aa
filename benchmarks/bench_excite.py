"""A designed excitation against the motions users record (issue 66): the worst standard error the identification
reports, as a share of its status's limit, on the same robot, duration and limits.

On a hung Go2 (PD drivers, a real driver's noise), for 30 s each:

* **designed**: ``wbfriction excite``'s design (:func:`wbfriction.excite.pd_design.design_pd`, defaults);
* **chirps**: each joint a sine about its posture whose frequency sweeps 0.2-2 Hz, over 0.25, 0.5 and 0.8 of each
  half range (``simulate``'s chirps);
* **Aliengo ramps**: the real Aliengo log's set-points (``../shared/real-data/unitree_aliengo``: triangle ramps, all
  legs alike, reversing after 1.5 s down to 0.3 s), each joint's moved onto the Go2's joint as the same share of
  its range about the Go2's posture, repeated from the start to fill 30 s.

Each is played by the hung simulator with a real driver's noise (two seeds) and identified as ``identify --actuator
pd`` does. The table gives per motion the worst share (standard error over its limit: offsets 0.01 rad, the others
0.25 x value; below 1: ``ok``), the parameters not ``ok`` and the delay's status; the designed one's predicted worst
beside it, and the ratio of each motion's worst to the designed one's (the issue's target: at least 3).

On a Panda (torque sensors, a real arm's sensors: :data:`~wbfriction.excite.predict_arm.REAL_ARM`), for 30 s each,
within 90 % of each joint's range and 80 % of its velocity limit: ``excite``'s Fourier design
(:func:`~wbfriction.excite.arm_design.design_arm`), a chirp of constant amplitude sweeping 0.05-1 Hz (its amplitude
what the velocity limit allows at 1 Hz), and triangle ramps at the velocity limit's 80 % with rounded reversals (5 %
of the range). Each is simulated with two noise seeds, estimated and fitted as ``estimate`` and ``fit`` do, the worst
share of F_c's and F_v's standard error read over 0.25 x value reported (below 1: not ``weak``); the torque margin
beside it (the simulator does not clip: a motion over its torque limit is not one a robot can play); and the worst
statistical share (the fit's standard error without the spread between model families, which the noise draws anew
per recording): what the design's Cramér-Rao bound is of.

    python benchmarks/bench_excite.py [--duration 30] [--seeds 7,8] [--no-arm]

Needs ``$WBFRICTION_DATA`` (or the dataset's download) for the Aliengo row; about 3 minutes on two cores, and 6 more
for the Panda's (``--no-arm`` skips them).
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace

import numpy as np
import pinocchio as pin

import wbfriction
from wbfriction.actuator import identify_actuators
from wbfriction.datasets.aliengo import ALIENGO_JOINTS, LOG_FILE, URDF_FILE, AliengoDataset, read_trajectory
from wbfriction.excite.arm_design import design_arm
from wbfriction.excite.design import ExciteOptions
from wbfriction.excite.limits import JointLimits, inverse_dynamics, margins
from wbfriction.excite.options import PdExciteOptions
from wbfriction.excite.pd_design import SHARE_LIMITS, design_pd
from wbfriction.excite.predict import Predicted, worst_share
from wbfriction.excite.predict_arm import REAL_ARM, identify_arm
from wbfriction.fit.status import WEAK
from wbfriction.logs.log import log_from_table
from wbfriction.sim.arm import default_arm_friction
from wbfriction.sim.hung import setpoint_band, simulate_hung
from wbfriction.sim.pd_options import REAL_DRIVER, HungOptions, SetpointOptions

CHIRP_AMPLITUDES = (0.25, 0.5, 0.8)


def aliengo_reference(robot, duration: float, rate: float) -> tuple[np.ndarray, np.ndarray]:
    """The real Aliengo's set-points moved onto ``robot``'s joints (module docstring): model angles and slopes
    (N, n_act)."""
    files = AliengoDataset().fetch()
    log = read_trajectory(files[LOG_FILE])
    model = pin.buildModelFromUrdf(str(files[URDF_FILE]))
    n = int(round(duration * rate))
    rows = np.arange(n) % len(log["time"])
    posture, low, high = setpoint_band(robot, 1.0)
    lower, upper = robot.angle_limits
    q = np.empty((n, robot.n_act))
    for i, joint in enumerate(robot.actuated):
        k = ALIENGO_JOINTS.index(joint)
        iq = model.joints[model.getJointId(joint)].idx_q
        share = (upper[i] - lower[i]) / (model.upperPositionLimit[iq] - model.lowerPositionLimit[iq])
        x = log["des_dof_pos"][:, k]
        q[:, i] = np.clip(posture[i] + share * (x[rows] - x[0]), low[i], high[i])
    return q, np.gradient(q, 1.0 / rate, axis=0)


def score(robot, options: HungOptions, reference=None) -> tuple[tuple[str, str, float], int, str]:
    """The worst share the identification reports on the motion, its parameters not ``ok``, the delay's status."""
    sim = simulate_hung(robot, options, reference=reference)
    result = identify_actuators(robot, log_from_table(sim.table, robot, "motion"))
    joints = {j.joint: j.parameters() for j in result.joints}
    not_ok = sum(p.status != "ok" for params in joints.values() for p in params.values())
    return worst_share(joints, SHARE_LIMITS, WEAK), not_ok, result.delay.status


ARM_RANGE, ARM_VELOCITY = 0.9, 0.8


def arm_motions(robot, duration: float):
    """The Panda's chirp and ramps (module docstring): each a callable of the times (N,) giving q, qd, qdd (N, n)."""
    lim = JointLimits.of(robot)
    middle, half = 0.5 * (lim.lower + lim.upper), 0.5 * (lim.upper - lim.lower) * ARM_RANGE
    v = ARM_VELOCITY * lim.velocity

    def chirp(t, f0=0.05, f1=1.0):
        a = np.minimum(half, v / (2 * np.pi * f1))
        phase = 2 * np.pi * (f0 * t + 0.5 * (f1 - f0) * t**2 / duration)
        w, dw = 2 * np.pi * (f0 + (f1 - f0) * t / duration), 2 * np.pi * (f1 - f0) / duration
        sin, cos = np.sin(phase)[:, None], np.cos(phase)[:, None]
        return middle + a * sin, a * cos * w[:, None], a * (-sin * w[:, None] ** 2 + cos * dw)

    def ramps(t, rounding=0.05):
        k = 1 - rounding
        ak = np.arcsin(k)
        om = v * ak / (k * half)  # the peak speed v
        x = np.outer(t, om)
        sin, cos = np.sin(x), np.cos(x)
        r = 1 - k**2 * sin**2
        return (middle + half * np.arcsin(k * sin) / ak, half * k * om * cos / np.sqrt(r) / ak,
                half * k * om**2 / ak * sin * (k**2 - 1) / r**1.5)
    return {"chirp": chirp, "ramps": ramps}


def arm_share(fits, read: bool) -> tuple[str, str, float]:
    """The worst share of F_c's and F_v's standard error over 0.25 x value among ``fits``: the one a user reads
    (``read``) or the statistical one (without the family spread)."""
    shares = {f.joint: {n: Predicted(getattr(f.params, n), 0.0, 0.0, (f.read_stderr() if read else f.stderr)[n], "",
                                     "") for n in ("F_c", "F_v")} for f in fits}
    return worst_share(shares, {}, WEAK)


def arm_rows(duration: float, seeds: list[int]) -> list[tuple[str, float, str, float, float, str]]:
    """Per Panda motion: its worst reported share (of F_c and F_v, over the seeds), where, its torque margin; its
    worst statistical share (the fit's standard error without the family spread: what the design's bound is of) and
    where."""
    robot = wbfriction.load_robot("panda")
    prior = default_arm_friction(robot)
    options = ExciteOptions(duration=duration, range_share=ARM_RANGE, velocity_share=ARM_VELOCITY)
    motions = {"designed": design_arm(robot, options, prior).design.trajectory, **arm_motions(robot, duration)}
    lim, t = JointLimits.of(robot), options.times()
    rows = []
    for name, motion in motions.items():
        q, qd, qdd = motion(t)
        torque = margins(lim, q, qd, inverse_dynamics(robot, q, qd, qdd, prior)).torque.min()
        worst, statistical = ("", "", 0.0), ("", "", 0.0)
        for seed in seeds:
            fits = [f for f in identify_arm(robot, prior, motion, replace(REAL_ARM, duration=duration, seed=seed))[1]
                    if f.params is not None]
            worst = max(worst, arm_share(fits, read=True), key=lambda w: w[2])
            statistical = max(statistical, arm_share(fits, read=False), key=lambda w: w[2])
        rows.append((name, worst[2], f"{worst[0]} {worst[1]}", torque, statistical[2],
                     f"{statistical[0]} {statistical[1]}"))
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--duration", type=float, default=30.0)
    parser.add_argument("--seeds", default="7,8")
    parser.add_argument("--no-arm", dest="arm", action="store_false", help="skip the Panda's rows")
    args = parser.parse_args()
    seeds = [int(s) for s in args.seeds.split(",")]
    robot = wbfriction.load_robot("go2")
    start = time.perf_counter()
    design = design_pd(robot, PdExciteOptions(duration=args.duration))
    designed_s = time.perf_counter() - start
    base = HungOptions(duration=args.duration, rate=design.options.rate)
    motions = {"designed": (design.options.hung(design.chosen.amplitude, design.chosen.reversal), None)}
    for a in CHIRP_AMPLITUDES:
        motions[f"chirps {a:g}"] = (replace(base, setpoints=SetpointOptions(kind="chirps", amplitude=a)), None)
    motions["Aliengo ramps"] = (base, aliengo_reference(robot, args.duration, base.rate))
    rows = []
    for name, (options, reference) in motions.items():
        scores = [score(robot, replace(options, noise=replace(REAL_DRIVER, seed=s)), reference) for s in seeds]
        worst = max(scores, key=lambda s: s[0][2])
        rows.append((name, worst[0], max(s[1] for s in scores), ",".join(sorted({s[2] for s in scores}))))
    mine = rows[0][1][2]
    print(f"Hung Go2, {args.duration:g} s, a real driver's noise, seeds {args.seeds}; the design took "
          f"{designed_s:.0f} s (chosen: ramps over {design.chosen.amplitude:g} of each half range, reversing every "
          f"{design.chosen.reversal[0]:g}-{design.chosen.reversal[1]:g} s; predicted worst {design.worst()[2]:.2f})\n")
    print("| motion | worst reported share | at | not ok (of 48) | delay | worst / designed's |")
    print("|---|---|---|---|---|---|")
    for name, (joint, param, share), not_ok, delay in rows:
        print(f"| {name} | {share:.2f} | {joint} {param} | {not_ok} | {delay} | {share / mine:.1f} |")
    if args.arm:
        arm = arm_rows(args.duration, seeds)
        print(f"\nPanda, {args.duration:g} s, a real arm's sensors, seeds {args.seeds}\n")
        print("| motion | worst reported share (F_c, F_v) | at | least torque margin | worst / designed's "
              "| worst statistical share | at | statistical / designed's |")
        print("|---|---|---|---|---|---|---|---|")
        for name, share, at, torque, stat, stat_at in arm:
            print(f"| {name} | {share:.3f} | {at} | {torque:.0%} | {share / arm[0][1]:.1f} | {stat:.3f} | {stat_at} "
                  f"| {stat / arm[0][4]:.1f} |")


if __name__ == "__main__":
    main()
