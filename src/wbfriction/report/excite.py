"""The figure of a designed excitation (``wbfriction excite --figure``): the set-points within each joint's limits,
and each parameter's predicted standard error as a share of its status's limit."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from wbfriction.logs.tables import write_atomic
from wbfriction.report.figures import png_bytes

FIGURE_DPI = 110


def excite_figure(path: str | Path, joints: tuple[str, ...], time: np.ndarray, q_des: np.ndarray,
                  lower: np.ndarray, upper: np.ndarray, shares: Mapping[str, Mapping[str, float]],
                  title: str, columns: int = 4) -> None:
    """Write the figure (PNG) of a design: per joint, its set-point ``q_des`` (N, n) [rad] against ``time`` (N,)
    [s] between its limits ``lower``, ``upper`` (n,) [rad] (dashed); below, per joint and parameter, the predicted
    standard error's share of its status's limit ``shares[joint][parameter]`` (below 1: predicted ``ok``).

    Raises:
        InputError, OutputError: what :func:`~wbfriction.logs.tables.write_atomic` raises.
    """
    n = len(joints)
    columns = min(columns, n)
    rows = int(np.ceil(n / columns))
    fig = Figure(figsize=(3.0 * columns, 1.7 * rows + 3.4), layout="constrained")
    top, bottom = np.asarray(fig.subfigures(2, 1, height_ratios=[1.7 * rows, 3.0])).ravel()
    axes = top.subplots(rows, columns, sharex=True, squeeze=False).ravel()
    for i, (ax, joint) in enumerate(zip(axes, joints)):
        ax.plot(time, q_des[:, i], lw=0.7, color="C0")
        for limit in (lower[i], upper[i]):
            ax.axhline(limit, color="0.4", lw=0.7, ls="--")
        ax.set_title(joint.replace("_joint", ""), fontsize=8)
        ax.tick_params(labelsize=7)
    for ax in axes[n:]:
        ax.set_visible(False)
    top.supxlabel("time from the start [s]", fontsize=8)
    top.supylabel("set-point [rad]", fontsize=8)
    names = list(dict.fromkeys(name for params in shares.values() for name in params))
    ax = bottom.subplots()
    width = 0.8 / max(len(names), 1)
    x = np.arange(n)
    for k, name in enumerate(names):
        values = [shares.get(j, {}).get(name, np.nan) for j in joints]
        ax.bar(x + (k - 0.5 * (len(names) - 1)) * width, values, width, label=name, color=f"C{k}")
    ax.axhline(1.0, color="C3", lw=0.8, ls="--", label="limit of ok")
    ax.set_xticks(x, [j.replace("_joint", "") for j in joints], rotation=30, ha="right", fontsize=7)
    ax.set_ylabel("predicted SE / limit of ok", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.legend(fontsize=7, ncols=len(names) + 1, loc="upper left")
    fig.suptitle(title, fontsize=9)
    write_atomic(path, lambda tmp: tmp.write_bytes(png_bytes(fig, dpi=FIGURE_DPI)))
