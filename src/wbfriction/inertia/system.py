"""The identification's least squares, compressed as it is built: a QR factorization of the rows seen so far,
so that a long log needs memory of the size of the parameter vector only
(:class:`~wbfriction.inertia.least_squares.CompressedLeastSquares`; :mod:`wbfriction.inertia.identification`).

Each joint's rows of each stance are compressed on their own, over the columns they can be non-zero in: the rooted
bodies' parameters beyond the joint (:attr:`~wbfriction.inertia.regressor.StanceRegressor.pattern`; on point feet
the floating model's, one group, each joint's rows where they hold: :attr:`~wbfriction.inertia.samples.Part.rows`)
and its own friction and armature (:func:`~wbfriction.inertia.rows.own_columns`). A QR costs the square of its
columns per row, and a joint's row is zero in most of them (on TALOS 8 to 317 of the 330 inertial columns, all but 4
of the 120 friction ones): about a tenth of the work of compressing the whole rows. The joints' factors are then
mapped to the original parameters and merged in one QR (the stacked rows' least squares, the same up to rounding).
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from wbfriction.inertia.least_squares import CompressedLeastSquares
from wbfriction.inertia.options import InertialOptions
from wbfriction.inertia.regressor import regressor_of, row_groups
from wbfriction.inertia.rows import friction_rows, own_columns, rest_names, row_mask, sample_rows
from wbfriction.inertia.samples import LogSamples
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress


def compressed_system(robot: Robot, samples: LogSamples, which: Literal["train", "validation"],
                      options: InertialOptions, progress: Progress | None = None) -> CompressedLeastSquares:
    """The compressed system of the rows ``which`` of every part of ``samples``
    (:func:`~wbfriction.inertia.samples.split_log`), in the original bodies' parameters (module docstring), the
    others after them (:func:`~wbfriction.inertia.rows.rest_names`); ``progress`` gets the samples done."""
    p_in = 10 * (robot.model.njoints - 1)
    p = p_in + len(rest_names(robot, options))
    own = own_columns(robot, options)
    merged = []
    for c in row_groups(robot):
        reg = regressor_of(robot, c)
        inertial = [np.flatnonzero(reg.pattern[i]) for i in robot.tc_index]
        systems = [CompressedLeastSquares(cols.size + own.shape[1], min_rows=4 * (cols.size + own.shape[1]))
                   for cols in inertial]
        for part in samples.parts:
            r = np.flatnonzero(getattr(part, which) & (part.stance == c))
            features = friction_rows(robot, part.kin, r, options)  # once: a global smoother filters the whole part
            for start in range(0, r.size, options.block):
                rr = r[start:start + options.block]
                Y, C, b = sample_rows(robot, part.kin, rr, c, options, features[start:start + options.block])
                rows = row_mask(part.holds(rr), C, b)
                for i, system in enumerate(systems):
                    keep = slice(None) if rows is None else rows[:, i]
                    system.add(np.column_stack([Y[keep, i][:, inertial[i]], C[keep, i][:, own[i]]]), b[keep, i])
                if progress is not None:
                    progress(rr.size)
        for i, system in enumerate(systems):
            to_joint = np.zeros((system.n, p))  # the joint's columns from the original parameters
            to_joint[:inertial[i].size, :p_in] = reg.to_rooted[inertial[i]]
            to_joint[np.arange(inertial[i].size, system.n), p_in + own[i]] = 1.0
            merged.append((system, to_joint))
    total = CompressedLeastSquares(p)
    total.absorb_all(merged)
    return total
