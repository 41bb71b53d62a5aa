"""Convert a KUKA LWR4+ recording (FloBaRoID's ``measurements_*.npz``) into the wbfriction log format.

Several recordings given together become one log, in the order given (their stamps must
increase): the time gap between them splits it into segments that are estimated apart.

The recording holds ``times`` (Unix epoch [s], as the recorder stamped them), ``positions`` [rad],
``torques`` [N·m] (the joint torque sensors), ``velocities`` [rad/s] (filtered by the controller)
and the controller's targets, for the joints ``lwr_0_joint`` ... ``lwr_6_joint`` in order. The log
keeps the stamps untouched (wbfriction decides how to read them) and writes

    time, q.<joint>, tau.<joint>, qd.<joint>

Nothing else is changed: no filter, no resampling. Usage::

    python examples/kuka_lwr4_convert.py ../shared/real-data/kuka_lwr4/measurements_1.npz -o run1.parquet
    python examples/kuka_lwr4_convert.py ../shared/real-data/kuka_lwr4/measurements_{1,2}.npz -o runs12.parquet
    wbfriction estimate run1.parquet --urdf ../shared/real-data/kuka_lwr4/kuka_lwr4.urdf \\
        --config examples/kuka_lwr4.toml -o run1_friction.parquet
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pyarrow as pa

from wbfriction.logs import write_table

JOINTS = tuple(f"lwr_{i}_joint" for i in range(7))


def convert(npz: Path) -> pa.Table:
    """The recording ``npz`` as a log table (columns above), one row per recorded sample."""
    data = np.load(npz)
    columns = {"time": np.asarray(data["times"], dtype=np.float64)}
    for prefix, key in (("q", "positions"), ("tau", "torques"), ("qd", "velocities")):
        values = np.asarray(data[key], dtype=np.float64)
        if values.shape != (len(columns["time"]), len(JOINTS)):
            raise SystemExit(f"{npz}: '{key}' has shape {values.shape}, expected ({len(columns['time'])}, 7)")
        columns.update({f"{prefix}.{j}": values[:, i] for i, j in enumerate(JOINTS)})
    return pa.table(columns)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("npz", type=Path, nargs="+", help="measurements_*.npz recordings")
    parser.add_argument("-o", "--output", type=Path, required=True, help="log to write (.parquet or .csv)")
    args = parser.parse_args()
    tables = [convert(p) for p in args.npz]
    write_table(pa.concat_tables(tables), args.output)
    step = np.concatenate([np.diff(t["time"].to_numpy()) for t in tables])
    print(f"{args.output}: {sum(t.num_rows for t in tables)} rows from {len(tables)} recording(s), {len(JOINTS)} "
          f"joints, time steps {step.min() * 1e3:.2f} to {step.max() * 1e3:.2f} ms within them (median "
          f"{np.median(step) * 1e3:.2f} ms), stamps kept as recorded")

if __name__ == "__main__":
    main()
