"""The longest differentiation window a walk's phases allow: half its shortest swing (issue 82).

No filter window spans a contact change (:mod:`wbfriction.signals.kinematics`): the rows whose central stencil
straddles one are left out of every filter, so that a sample is estimated only where its whole window lies inside one
phase. A swing of ``P`` samples (a foot's flag down from its lift-off at row ``a`` to its touch-down at ``a + P``)
straddles its two changes on its first and last rows; a window of ``L`` samples (a Savitzky-Golay window, or the
momentum route's velocity and momentum windows together, ``L_v + L_m - 1``) then leaves

.. math::

    P - 2 - (L - 1) = P - 1 - L

of its samples with their window inside it, and none once ``L >= P - 1``. A window chosen from the noise alone knows
nothing of the phases: on a trotting robot's log it came out 517 samples (0.63 s) against swings of 0.15 s, and every
swing was lost.

The bound: a window may cost a swing at most as many samples as it leaves it, ``L + 1 <= P - 1 - L``, that is
``L <= (P - 2) / 2`` (:func:`window_bound`): the shortest swing keeps at least half its samples, every longer one more.
It follows from how the window's support meets the phase, not from any log. Swings that are lost whatever the window
do not bound it (:meth:`Swings.shortest`): those no longer than the thesis's margins after a lift-off and before a
touch-down together (6.2.1: nothing of them is estimated; a flag's glitch, a foot's bounce on a soft contact: 22
samples of a noisy MuJoCo walk against swings of 119), and those too short for the least window of a scheme to keep
half of them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def window_bound(samples: int) -> int:
    """The longest odd window [samples] that a phase of ``samples`` keeps at least half of (module docstring):
    the largest odd ``L <= (samples - 2) / 2``; below 1 for a phase shorter than 4 samples."""
    half = (samples - 2) // 2
    return half if half % 2 else half - 1


def samples_left(window: int, samples: int) -> int:
    """The samples of a phase of ``samples`` whose window of ``window`` samples lies inside it (module docstring)."""
    return max(0, samples - 1 - window)


@dataclass(frozen=True)
class Swing:
    """One swing: a foot's flag down from a lift-off to a touch-down.

    Attributes:
        frame: the foot's contact frame.
        start: the lift-off's row (the first row off the ground); samples: the rows off the ground.
        seconds: its duration [s] (``samples`` times the period).
    """

    frame: str
    start: int
    samples: int
    seconds: float


@dataclass(frozen=True)
class Swings:
    """The complete swings of a log (each lift-off and touch-down inside one stretch between time gaps): the phases a
    window must resolve on a robot whose feet leave the ground (:func:`log_swings`)."""

    swings: tuple[Swing, ...]
    stretches: tuple[Swing, ...] = ()

    def shortest_stretch(self, least_window: int = 1) -> Swing | None:
        """The shortest of :attr:`stretches` (the rows estimated while a foot swings, :func:`log_swings`) whose bound
        is at least ``least_window``, or None."""
        kept = [s for s in self.stretches if window_bound(s.samples) >= least_window]
        return min(kept, key=lambda s: (s.samples, s.start)) if kept else None

    def shortest(self, least_window: int = 1, margins: float = 0.0) -> Swing | None:
        """The shortest swing longer than ``margins`` [s] (the lift-off and touch-down margins together) whose bound
        (:func:`window_bound`) is at least ``least_window`` (the least window of the scheme), or None: a shorter one
        is lost whatever the window (module docstring)."""
        kept = [s for s in self.swings if window_bound(s.samples) >= least_window and s.seconds > margins + 1e-9]
        return min(kept, key=lambda s: (s.samples, s.start)) if kept else None

    def longest(self) -> Swing | None:
        """The longest swing, or None."""
        return max(self.swings, key=lambda s: (s.samples, -s.start)) if self.swings else None


def log_swings(contact: np.ndarray, frames: tuple[str, ...], dt: float,
               segments: list[tuple[int, int]] | None = None, margins: tuple[float, float] | None = None) -> Swings:
    """Every complete swing of a log's contact flags (module docstring), and with ``margins`` the stretches a point
    feet route estimates while a foot swings.

    Args:
        contact: (N, n_c) the contact flags; frames: their frames (n_c,); dt: the sampling period [s].
        segments: the row ranges between time gaps (None: one): a swing that a gap or the log's end cuts is not
            complete (its length not known) and is left out.
        margins: the lift-off and touch-down margins [s] (:func:`~wbfriction.signals.phases.settled`): the
            stretches are the runs of rows with a foot off the ground outside every margin (a window that must lie
            whole inside the rows estimated, the momentum route's, is bounded by them); None: none.
    """
    contact = np.asarray(contact, dtype=bool)
    out: list[Swing] = []
    for a, b in segments or [(0, len(contact))]:
        for c, frame in enumerate(frames):
            on = contact[a:b, c]
            edges = np.flatnonzero(on[1:] != on[:-1]) + 1  # rows where the flag changes
            for lift, down in zip(edges[:-1], edges[1:]):
                if not on[lift]:  # a lift-off at ``lift``, a touch-down at ``down``
                    n = int(down - lift)
                    out.append(Swing(frame, int(a + lift), n, n * dt))
    stretches = () if margins is None else _stretches(contact, frames, dt, segments, margins)
    return Swings(tuple(sorted(out, key=lambda s: (s.start, s.frame))), stretches)


def _stretches(contact: np.ndarray, frames: tuple[str, ...], dt: float, segments: list[tuple[int, int]] | None,
               margins: tuple[float, float]) -> tuple[Swing, ...]:
    """The complete runs of rows with a foot off the ground and outside every switch's margins (:func:`log_swings`),
    each named by the feet off the ground at its start."""
    from wbfriction.signals.phases import settled

    out = []
    for a, b in segments or [(0, len(contact))]:
        on = contact[a:b]
        keep = np.r_[False, settled(np.arange(b - a) * dt, on, *margins) & ~on.all(axis=1), False]
        edges = np.flatnonzero(keep[1:] != keep[:-1])
        for start, stop in zip(edges[::2], edges[1::2]):
            if start > 0 and stop < b - a:  # a run the log's ends cut is not complete
                off = "+".join(f for f, c in zip(frames, on[start]) if not c)
                out.append(Swing(off, int(a + start), int(stop - start), (stop - start) * dt))
    return tuple(out)
