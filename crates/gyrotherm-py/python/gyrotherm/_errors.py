"""The base of every gyrotherm exception (the compiled module derives the others from it).

It is written in Python because it has two bases: ``ValueError``, since gyrotherm's errors
are bad values (a log line, a model field, a sample rate), and ``RuntimeError``, since the
allantools functions gyrotherm stands in for (``adev`` … ``tdev``) raise ``RuntimeError`` for
the same faults (a zero sample rate) and code written against allantools catches that.
Both built-in classes add no fields to ``BaseException``, so Python accepts them together.
"""


class GyrothermError(ValueError, RuntimeError):
    """Base of every gyrotherm error; the message names the file, line and column where one
    is at fault, and what to do. Catchable as ``ValueError`` and as ``RuntimeError``."""


# Shown and pickled as `gyrotherm.GyrothermError`, the name users import it by.
GyrothermError.__module__ = "gyrotherm"
