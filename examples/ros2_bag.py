"""A ROS 2 bag as a log: a topic map names the joint states and the contact topics; no ROS installation.

    python examples/ros2_bag.py                       # writes a small bag from a simulated walk, then reads it
    python examples/ros2_bag.py --write robot_bag     # only writes it (its map: examples/inputs/bag_map.toml)
    python examples/ros2_bag.py my_bag/ --map map.toml

The samples are the joint-state messages at their header stamps; each contact flag is the latest
``std_msgs/Bool`` (or a ``geometry_msgs/WrenchStamped`` over a threshold) at or before a sample.
"""

from __future__ import annotations

import argparse
import dataclasses
import tempfile
from pathlib import Path

import numpy as np

import wbfriction
from wbfriction.fit.targets import THESIS_TARGETS, friction_by_group
from wbfriction.pipeline import convert_log
from wbfriction.sim import IdealOptions, simulate_ideal
from wbfriction.walking import GaitOptions, walking_reference

MAP_TOML = Path(__file__).with_name("inputs") / "bag_map.toml"
"""The topic map of the bags this example writes (:func:`write_bag`)."""


def write_bag(path: Path, log: wbfriction.Log, robot: wbfriction.Robot) -> None:
    """The log as an MCAP bag: JointState at every sample, each foot's contact as a Bool when it changes."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    T = ts.types
    effort = np.zeros((len(log), robot.n_act))
    effort[:, robot.tc_index] = log.tau
    with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as bag:
        joints = bag.add_connection("/joint_states", "sensor_msgs/msg/JointState", typestore=ts)
        feet = [bag.add_connection(f"/{side}_foot_contact", "std_msgs/msg/Bool", typestore=ts)
                for side in ("left", "right")]
        for k in range(len(log)):
            ns = 1_700_000_000_000_000_000 + int(round(log.time[k] * 1e9))  # stamps as a robot writes them
            stamp = T["builtin_interfaces/msg/Time"](sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)
            for c, foot in enumerate(feet):
                if k == 0 or log.contact[k, c] != log.contact[k - 1, c]:
                    bag.write(foot, ns - 1, ts.serialize_cdr(T["std_msgs/msg/Bool"](data=bool(log.contact[k, c])),
                                                             "std_msgs/msg/Bool"))
            msg = T["sensor_msgs/msg/JointState"](header=T["std_msgs/msg/Header"](stamp=stamp, frame_id=""),
                                                  name=list(robot.actuated), position=np.ascontiguousarray(log.q[k]),
                                                  velocity=np.zeros(0),
                                                  effort=effort[k])
            bag.write(joints, ns, ts.serialize_cdr(msg, "sensor_msgs/msg/JointState"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("bag", nargs="?", type=Path, help="a ROS 2 bag folder (default: write one)")
    parser.add_argument("--map", type=Path, help="its topic map TOML (default: the one of the written bag)")
    parser.add_argument("--steps", type=int, default=2, help="steps of the simulated walk")
    parser.add_argument("--write", type=Path, help="only write the simulated walk's bag into this new folder")
    args = parser.parse_args()
    robot = wbfriction.load_robot("talos")
    out = Path(tempfile.mkdtemp(prefix="wbfriction-bag-"))
    bag, topic_map, walk = args.bag, args.map, None
    if bag is None:
        reference = walking_reference(robot, GaitOptions(gait="forward", steps=args.steps))
        friction = friction_by_group(robot.groups, THESIS_TARGETS)
        walk = simulate_ideal(robot, reference, friction, IdealOptions(substeps=10))
        bag, topic_map = args.write or out / "walk_bag", MAP_TOML
        write_bag(bag, walk.log, robot)
        if args.write:
            print(f"wrote {bag} ({len(walk.log)} samples; its topic map: {MAP_TOML})")
            return

    source = wbfriction.open_log(bag, topic_map)  # decides once: a bag, read through its map
    print(f"{bag}: a {source.format} log")
    log = wbfriction.read_log(bag, robot, topic_map)
    estimate = wbfriction.estimate_log(robot, log)
    knee = estimate.joints.index("leg_right_4_joint")
    valid = estimate.valid[:, knee]
    print(f"{len(log)} samples; right knee: {int(valid.sum())} valid samples, mean tau_f "
          f"{estimate.tau_f[valid, knee].mean():+.3f} N·m")
    if walk is not None:  # the bag holds the simulated log but its base pose: the same estimate, sample for sample
        direct = wbfriction.estimate_log(robot, dataclasses.replace(walk.log, base=None))
        print(f"largest difference to the log's own estimate: "
              f"{np.nanmax(np.abs(direct.tau_f[valid] - estimate.tau_f[valid])):.2e} N·m")
    rows = convert_log(robot, bag, out / "log.parquet", topic_map)  # or keep it as a log file
    print(f"wrote {out / 'log.parquet'} ({rows} samples)")


if __name__ == "__main__":
    main()
