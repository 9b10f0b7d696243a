"""The one error type the command line turns into a one-line message and exit code 2, and where it happened."""


class InputError(ValueError):
    """Bad user input (scenario file, option, geometry). ``str(err)`` is one line saying what and where."""


def one_line(text: str) -> str:
    """``text`` on one line: every run of whitespace (newlines included) becomes one space."""
    return " ".join(str(text).split())


class InputContext:
    """Where we are in an input file, for error messages: ``error(where, message)`` gives
    ``InputError("fname: where message")`` on one line; ``base_dir`` resolves the file's relative paths."""

    def __init__(self, fname: str, base_dir: str):
        self.fname = fname
        self.base_dir = base_dir

    def error(self, where: str, message: str) -> InputError:
        where = f"{where} " if where else ""
        return InputError(one_line(f"{self.fname}: {where}{message}"))
