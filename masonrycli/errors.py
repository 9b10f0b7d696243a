"""The one error type the command line turns into a one-line message and exit code 2."""


class InputError(ValueError):
    """Bad user input (scenario file, option, geometry). ``str(err)`` is one line saying what and where."""
