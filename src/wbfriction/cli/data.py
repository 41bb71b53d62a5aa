"""``wbfriction dataset``: real robots' logs, fetched and checked, written as logs with the robot beside them."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Literal

import typer

# Loading this module (what `wbfriction --help` and every command pay before they start) imports only the
# options, whose defaults the help shows: each command imports the rest of the library when it runs.

if TYPE_CHECKING:
    pass

from wbfriction.cli.common import (
    app,
    console,
    out,
)


@app.command()
def dataset(name: Literal["kuka-lwr4"] = typer.Argument(..., metavar="NAME",
                                                       help="The dataset: kuka-lwr4 (FloBaRoID's KUKA LWR4+: three "
                                                            "runs of 25 s, link-side joint torque sensors, about "
                                                            "6 MB)."),
            output_dir: Path = typer.Option(..., "-o", "--output-dir",
                                            help="Folder to write into (made if missing): runs12.parquet (runs 1 "
                                                 "and 2), run3.parquet (run 3, held out), the robot's URDF and "
                                                 "its configuration kuka_lwr4.toml.")) -> None:
    """Fetch a real robot's logs and write them as wbfriction logs with the robot beside them: downloaded once
    into the user's cache, each file checked against its SHA-256, or taken from $WBFRICTION_DATA/<dataset>/ (a
    local copy, for offline machines, checked the same way). Prints the commands to run next."""
    import shlex

    from wbfriction.datasets import write_kuka_lwr4_logs

    with console.status("fetching the KUKA LWR4+ dataset"):
        logs = write_kuka_lwr4_logs(output_dir)
    console.print(f"wrote {logs.runs12} ({logs.rows[0]} samples: runs 1 and 2), {logs.run3} ({logs.rows[1]} "
                  f"samples: run 3) and the robot, {logs.config}", highlight=False, markup=False)
    robot = f"--config {shlex.quote(str(logs.config))}"
    runs12, run3 = shlex.quote(str(logs.runs12)), shlex.quote(str(logs.run3))
    for line in ("next:", f"  wbfriction estimate {runs12} {robot} -o runs12_friction.parquet",
                 "  wbfriction fit runs12_friction.parquet -o runs12_params.json",
                 f"  wbfriction estimate {run3} {robot} -o run3_friction.parquet",
                 "  wbfriction predict run3_friction.parquet --params runs12_params.json",
                 f"  wbfriction identify {runs12} {robot} -o kuka_identified.urdf"):
        out.print(line, highlight=False, markup=False, soft_wrap=True)


