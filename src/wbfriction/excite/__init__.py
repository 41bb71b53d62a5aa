"""Excitation design: the motion to record so that a log determines every parameter asked for (issue 66)."""
