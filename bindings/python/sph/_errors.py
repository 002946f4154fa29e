# SPDX-License-Identifier: MIT
"""SphError: a failed sph_ call, with its sph_result code and the library's message."""
from . import _generated as _g


class SphError(Exception):
    """A call into the sph library failed.

    Attributes:
        result: the sph_result code (a :class:`sph.Result` member, or a plain int for a code
            this binding does not know).
        message: the library's explanation (sph_get_last_error() right after the call).
        function: the C function that failed, e.g. ``"sph_world_create"``.
    """

    def __init__(self, result, message="", function=None):
        try:
            result = _g.Result(result)
            name = "SPH_" + result.name
        except ValueError:
            name = f"sph_result {result}"
        self.result = result
        self.message = message
        self.function = function
        where = f"{function}: " if function else ""
        super().__init__(f"{where}{name}: {message}" if message else f"{where}{name}")


class SphLoadError(ImportError):
    """The sph shared library could not be found or loaded, or does not match these bindings."""


def last_error():
    """The message of the last failed sph_ call on this thread ("" after a success)."""
    from ._loader import library

    return library().sph_get_last_error().decode("utf-8", "replace")


def check(code, function):
    """Raises SphError for a negative sph_result; returns the Result otherwise (OK, INCOMPLETE)."""
    if code < 0:
        raise SphError(code, last_error(), function)
    try:
        return _g.Result(code)
    except ValueError:
        return code
