"""What a SciPy solver's stopping message means for the result, in one phrase a user can act on.

SciPy reports why a solver stopped in its own words (``"The maximum number of function evaluations is
exceeded."``, ``"Desired error not necessarily achieved due to precision loss."``,
``"ABNORMAL_TERMINATION_IN_LNSRCH"``, ``lsq_linear``'s and ``least_squares``' status codes). Printed raw,
they say nothing of whether the numbers can be used. :func:`explain_solver` maps each known message
(``scipy.optimize.least_squares``, ``lsq_linear``, ``minimize``'s BFGS / CG / Nelder-Mead / SLSQP and
L-BFGS-B, old and new spellings) to whether the solver converged and what that means for the
parameters; an unknown one passes through with a neutral phrase. The raw message is kept
(:attr:`SolverOutcome.raw`) for experts: ``wbfriction identify --json`` writes both.
"""

from __future__ import annotations

from dataclasses import dataclass

NOT_A_MINIMUM = "the parameters are not a minimum of the fit"

_KNOWN: tuple[tuple[tuple[str, ...], bool, str], ...] = (
    # (substrings of the lower-cased message with "_" as " ", converged, meaning)
    (("maximum number of function evaluations", "f,g evaluations exceeds limit"), False,
     f"stopped at its evaluation limit before converging: {NOT_A_MINIMUM}"),
    (("maximum number of iterations", "iterations reached limit", "iteration limit reached"), False,
     f"stopped at its iteration limit before converging: {NOT_A_MINIMUM}"),
    (("precision loss", "rounding errors prevent progress"), False,
     "stopped where rounding errors hid any further decrease: near a minimum at best, not certainly at one"),
    (("abnormal termination in lnsrch", "abnormal"), False,
     "stopped when its line search failed (an inaccurate gradient or a badly scaled problem): "
     f"{NOT_A_MINIMUM}, as far as it knows"),
    (("positive directional derivative for linesearch",), False,
     f"stopped when its line search found no descent: {NOT_A_MINIMUM}, as far as it knows"),
    (("not able to make progress",), False,
     "stalled: its last step did not decrease the cost, possibly short of the minimum"),
    (("nan result encountered",), False, "met a NaN: the model could not be evaluated there; no result"),
    (("improper input",), False, "was given improper input: no result"),
    (("callback", "stopiteration"), False, f"was stopped by a callback: {NOT_A_MINIMUM}"),
    (("outside of the provided bounds",), False, "ended outside its bounds: the parameters are not admissible"),
    (("cpu exceeding the time limit",), False, f"stopped at its time limit: {NOT_A_MINIMUM}"),
    (("both `ftol` and `xtol`", "both ftol and xtol"), True, "converged: neither the cost nor the parameters "
                                                             "changed any more"),
    (("`gtol` termination", "gtol termination", "norm of projected gradient", "projected gradient is "
      "sufficiently small", "first-order optimality measure is less than"), True,
     "converged: the gradient vanished (a minimum within the bounds)"),
    (("`ftol` termination", "ftol termination", "reduction of f <= factr", "relative change of the cost "
      "function is less than"), True, "converged: the cost stopped decreasing"),
    (("`xtol` termination", "xtol termination", "xtol test satisfied"), True,
     "converged: the parameters stopped changing"),
    (("unconstrained solution is optimal",), True, "converged: the unconstrained solution is within the bounds"),
    (("optimization terminated successfully",), True, "converged"),
)

_LEAST_SQUARES_STATUS = {-2: "callback", -1: "improper input", 0: "maximum number of function evaluations",
                         1: "gtol termination", 2: "ftol termination", 3: "xtol termination",
                         4: "both ftol and xtol"}
"""``scipy.optimize.least_squares``' status codes, as the message text they stand for (used without a message)."""


@dataclass(frozen=True)
class SolverOutcome:
    """Why a solver stopped, for the result.

    Attributes:
        raw: the solver's own message ("" when no solver ran).
        status: its status code (``least_squares``: -2 … 4; None when not known).
        converged: whether it stopped at a minimum (None: not known, an unknown message).
        meaning: what that means for the result, one phrase beginning with a verb ("converged: …",
            "stopped at its evaluation limit before converging: …").
    """

    raw: str
    status: int | None
    converged: bool | None
    meaning: str

    def to_dict(self) -> dict:
        """JSON-ready: ``converged``, ``meaning``, ``raw_message``, ``status``."""
        return {"converged": self.converged, "meaning": self.meaning, "raw_message": self.raw, "status": self.status}


def explain_solver(message: str | bytes | None, status: int | None = None) -> SolverOutcome:
    """What a SciPy solver's stopping ``message`` (and, without one, ``least_squares``' ``status``) means
    (module docstring). Unknown messages pass through: ``"stopped (the solver said: …); whether at a
    minimum is not known"``."""
    raw = message.decode(errors="replace") if isinstance(message, bytes) else (message or "")
    text = raw.strip().lower().replace("_", " ")
    if not text and status is not None:
        text = _LEAST_SQUARES_STATUS.get(int(status), "")
    for needles, converged, meaning in _KNOWN:
        if any(n in text for n in needles):
            return SolverOutcome(raw, status, converged, meaning)
    if not text:
        return SolverOutcome(raw, status, None, "gave no reason for stopping; whether at a minimum is not known")
    return SolverOutcome(raw, status, None,
                         f"stopped (the solver said: {raw.strip().rstrip('.')}); whether at a minimum is not known")
