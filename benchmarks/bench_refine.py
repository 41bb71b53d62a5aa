"""Issue 64's refinement on the hung Go2, whose truth is known: the route a user runs, timed, and what it finds.

A 14 s log of the hung Go2 (12 joints, 200 Hz, a real driver's noise; ``--friction`` ``model``, the simulator's
smooth Coulomb-viscous law, or ``mujoco``, MuJoCo's own friction loss and damping, the export's model class) is cut
60/40. On the first 60 % the PD how-to's route runs as commands (``identify --actuator pd --config-output``,
``estimate``, ``fit --model coulomb-viscous --terms none``, ``export`` to MJCF, ``refine``), each timed; the route's
wall time is printed against issue 64's 2 minutes and PACE's published 2 h 15 min (CMA-ES over Isaac Lab on an RTX
3080, ANYmal). Then the export, the refined file and the truth's own file (written from the log's metadata) are
replayed on the last 40 % at the simulator's 1 ms (``--timestep``), and the refined values are compared with the
truth (the armature as MuJoCo's Euler step holds it, less ``h F_v``: :mod:`wbfriction.replay.refine`), each error in its
standard errors. With ``--true-offsets`` the refinement runs with the truth's encoder offsets (what it does not
refine) instead of the identified ones, the export written again with them (a file's actuators hold the offsets it
was exported with: ``wbfriction.replay.feasibility``).

    python benchmarks/bench_refine.py [--friction model|mujoco] [--timestep 0.001] [--true-offsets] [--keep DIR]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import tempfile
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq

from wbfriction.export.mjcf import write_mjcf
from wbfriction.friction.models import params_from_dict
from wbfriction.model.loading import load_robot
from wbfriction.replay.mjcf import Replay, replay_mjcf
from wbfriction.replay.refine import PARAMETERS
from wbfriction.studies.real_data import run_route

PACE_SECONDS = 2 * 3600 + 15 * 60
"""PACE's published identification time of ANYmal (CMA-ES over Isaac Lab rollouts on an RTX 3080) [s]."""
TARGET_SECONDS = 120.0
"""Issue 64: identification plus refinement within 2 minutes on two cores for a 14 s, 12-joint log [s]."""


def split(folder: Path) -> dict:
    """The log cut 60/40 into ``train.parquet`` and ``held_out.parquet``; its truth (the metadata)."""
    table = pq.read_table(folder / "hung.parquet")
    k = int(0.6 * table.num_rows)
    pq.write_table(table.slice(0, k), folder / "train.parquet")
    pq.write_table(table.slice(k), folder / "held_out.parquet")
    return json.loads(table.schema.metadata[b"wbfriction"])


def truth_file(truth: dict, path: Path):
    """The MJCF of the truth (the built-in go2's drivers, the log's offsets, friction and armature); its robot."""
    robot = dataclasses.replace(load_robot("go2"), encoder_offset=truth["encoder_offset_true"], cache={})
    friction = {j: params_from_dict(d["model"], {k: v for k, v in d.items() if k != "model"})
                for j, d in truth["friction_true"].items()}
    write_mjcf(robot, friction, path, armature=truth["armature_true"])
    return robot


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--friction", choices=("model", "mujoco"), default="model")
    parser.add_argument("--timestep", type=float, default=0.001, help="the refinement's and replays' step [s]")
    parser.add_argument("--true-offsets", action="store_true")
    parser.add_argument("--keep", type=Path, default=None)
    args = parser.parse_args()
    folder = args.keep or Path(tempfile.mkdtemp(prefix="bench_refine-"))
    folder.mkdir(parents=True, exist_ok=True)
    mujoco_friction = " --mujoco-friction mujoco --friction-timeconst 0.02" if args.friction == "mujoco" else ""
    run_route([f"wbfriction simulate --robot go2 --duration 14{mujoco_friction} -o hung.parquet"], folder)
    truth = split(folder)
    truth_robot = truth_file(truth, folder / "truth.xml")
    config = "go2_identified.toml"
    route = ["wbfriction identify train.parquet --robot go2 --actuator pd --config-output go2_identified.toml",
             f"wbfriction estimate train.parquet --config {config} -o train_friction.parquet",
             "wbfriction fit train_friction.parquet --model coulomb-viscous --terms none -o cv.json",
             f"wbfriction export cv.json --config {config} --include weak,at-bound -o go2.xml"]
    timed = list(run_route(route, folder))
    exported = "go2.xml"
    if args.true_offsets:  # the file exported with them: a file's actuators hold the offsets it was exported with
        text = (folder / config).read_text().split("[encoder_offset]")[0]
        offsets = "\n".join(f"{j} = {v!r}" for j, v in truth["encoder_offset_true"].items())
        (folder / "go2_true_offsets.toml").write_text(f"{text}[encoder_offset]\n{offsets}\n")
        config, exported = "go2_true_offsets.toml", "go2_true_offsets.xml"
        run_route([f"wbfriction export cv.json --config {config} --include weak,at-bound -o {exported}"], folder)
    timed += run_route([f"wbfriction refine train.parquet {exported} --config {config} -o refined.xml "
                        f"--timestep {args.timestep!r} --table refined.parquet"], folder)
    total = sum(t.seconds for t in timed)
    print(f"hung Go2, 14 s, friction {args.friction}, refined at {1e3 * args.timestep:g} ms"
          + (", the truth's encoder offsets" if args.true_offsets else ""))
    print("| command | wall [s] |\n|---|---|")
    for t in timed:
        print(f"| {t.command.split()[1]} | {t.seconds:.1f} |")
    print(f"| route | {total:.1f} ({total / TARGET_SECONDS:.2f} of the 2 min target; PACE's 2 h 15 min / ours = "
          f"{PACE_SECONDS / total:.0f}) |")
    robot = load_robot(None, config=folder / config)
    replay = Replay(timestep=args.timestep)
    print("\n| held-out, 1 s windows [mrad] | mean | worst |\n|---|---|---|")
    for label, path, who in (("export", exported, robot), ("refined", "refined.xml", robot),
                             ("the truth's file", "truth.xml", truth_robot)):
        rms = 1e3 * replay_mjcf(folder / path, who, folder / "held_out.parquet", replay).rms
        print(f"| {label} | {rms.mean():.2f} | {rms.max():.2f} |")
    values = pq.read_table(folder / "refined.parquet").to_pydict()
    n = len(robot.actuated)
    value, se, start = (np.array(values[k]).reshape(len(PARAMETERS) + 1, n) for k in ("value", "stderr", "start"))
    joints = values["joint"][:n]
    f_c, f_v = (np.array([truth["friction_true"][j][k] for j in joints]) for k in ("F_c", "F_v"))
    arm = np.array([truth["armature_true"][j] for j in joints]) - args.timestep * f_v
    print("\n| value | truth | start: worst error | refined: worst error | worst in SE | within 2 SE |\n"
          "|---|---|---|---|---|---|")
    for k, (name, true) in enumerate((("armature", arm), ("F_c", f_c), ("F_v", f_v))):
        z = np.abs(value[k] - true) / se[k]
        print(f"| {name} | {'armature - h F_v' if k == 0 else name} | {100 * np.abs(start[k] / true - 1).max():.1f} % "
              f"| {100 * np.abs(value[k] / true - 1).max():.1f} % | {z.max():.1f} | {int(np.sum(z <= 2))} of {n} |")
    delay = truth["delay_true"]
    print(f"| delay [ms] | {1e3 * delay:g} | {1e3 * abs(start[4, 0] - delay):.2f} ms | "
          f"{1e3 * abs(value[4, 0] - delay):.2f} ms | {abs(value[4, 0] - delay) / se[4, 0]:.1f} | "
          f"(whole steps of {1e3 * args.timestep:g} ms) |")
    print(f"\nkept in {folder}" if args.keep else "")


if __name__ == "__main__":
    sys.exit(main())
