"""WaferScan's error types, one hierarchy (as shapely's ``errors.py`` keeps its own).

Every error the package raises on purpose derives from ``WaferScanError``, so a caller that
shows errors to a user (the GUI's commands, the command line) catches that one type:

>>> try:
...     raise InputError("paper.toml", 3, "pitch: expected a number")
... except WaferScanError as exc:
...     print(exc)
paper.toml:3: pitch: expected a number
"""


class WaferScanError(Exception):
    """The base of every error WaferScan raises on purpose (not a fault of its own code)."""


class InputError(WaferScanError):
    """Bad input from a user: names the file, the line (1-based, or None) and what is wrong.

    The command line prints ``str(error)`` after ``waferscan: error:`` and exits with status 2.
    """

    def __init__(self, source, line, message):
        self.source = str(source)
        self.line = line
        self.message = message
        super().__init__(str(self))

    def __str__(self):
        where = self.source if self.line is None else f"{self.source}:{self.line}"
        return f"{where}: {self.message}"


class ShapeError(WaferScanError, ValueError):
    """A solid that is not what its role needs (a wafer that is not a flat disc). A ValueError
    too, as it was before the hierarchy."""


class EngineError(WaferScanError, ValueError):
    """A scan asked of an engine that does not offer it (exact edges of a stepped engine)."""
