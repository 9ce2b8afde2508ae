"""The one error type for a user's mistake in an input file or argument."""


class InputError(Exception):
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
