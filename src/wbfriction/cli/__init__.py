"""Command-line interface: a thin layer over the library, one module per group of commands.

Commands: ``simulate`` (a walk with known friction), ``estimate`` (friction per sample), ``fit`` (a model per
joint), ``rollout`` (an exported MJCF replayed under a log's set-points), ``refine`` (its parameters
refined on that replay's error), ``identify`` (inertia model and friction
together, corrected URDF), ``report`` (one HTML file), ``sensitivity`` (inertia-model errors), ``spectrum``, ``demo``
and the ``study-*`` commands (the thesis's studies and this project's), ``batch`` and ``trends`` (fleets),
``dataset`` (real logs). Bad input prints one line naming the file, column, row or option at fault and exits with
status 2.
"""

# the commands, registered in the order a user meets them (``wbfriction --help`` lists them so)
# isort: off
from wbfriction.cli import simulate, estimate, fit, rollout, refine, identify, excite, studies, fleet, data  # noqa: F401
# isort: on
from wbfriction.cli.common import app, main

__all__ = ["app", "main"]
