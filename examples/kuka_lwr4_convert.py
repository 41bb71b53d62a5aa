"""Convert KUKA LWR4+ recordings (FloBaRoID's ``measurements_*.npz``) into the wbfriction log format.

A thin wrapper over :func:`wbfriction.logs.read_npz_recordings` (what ``wbfriction dataset kuka-lwr4``
uses too, after fetching the recordings): several recordings given together become one log, in the
order given (their stamps must increase); the time gap between them splits it into segments that are
estimated apart. The log keeps the stamps untouched (wbfriction decides how to read them) and holds

    time, q.<joint>, tau.<joint>, qd.<joint>

for the joints ``lwr_0_joint`` ... ``lwr_6_joint``. Nothing else is changed: no filter, no resampling.
Usage::

    python examples/kuka_lwr4_convert.py ../shared/real-data/kuka_lwr4/measurements_1.npz -o run1.parquet
    python examples/kuka_lwr4_convert.py ../shared/real-data/kuka_lwr4/measurements_{1,2}.npz -o runs12.parquet
    wbfriction estimate run1.parquet --urdf ../shared/real-data/kuka_lwr4/kuka_lwr4.urdf \\
        --config examples/kuka_lwr4.toml -o run1_friction.parquet
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from wbfriction.datasets import KUKA_LWR4_JOINTS
from wbfriction.logs import read_npz_recordings, write_table


def samples(npz: Path) -> int:
    """The samples of a recording (the length of its ``times``)."""
    with np.load(npz) as recording:
        return len(recording["times"])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("npz", type=Path, nargs="+", help="measurements_*.npz recordings")
    parser.add_argument("-o", "--output", type=Path, required=True, help="log to write (.parquet or .csv)")
    args = parser.parse_args()
    table = read_npz_recordings(args.npz, KUKA_LWR4_JOINTS)
    write_table(table, args.output)
    ends = np.cumsum([samples(p) for p in args.npz])  # each recording's last row + 1
    step = np.delete(np.diff(table["time"].to_numpy()), ends[:-1] - 1)  # the steps between recordings left out
    print(f"{args.output}: {table.num_rows} rows from {len(args.npz)} recording(s), {len(KUKA_LWR4_JOINTS)} "
          f"joints, time steps {step.min() * 1e3:.2f} to {step.max() * 1e3:.2f} ms within them (median "
          f"{np.median(step) * 1e3:.2f} ms), stamps kept as recorded")


if __name__ == "__main__":
    main()
