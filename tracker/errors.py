"""The one error type that the command line turns into a single line and exit status 2."""


class InputError(Exception):
    """A bad input file or configuration: missing, empty, corrupt, wrong topic, bad value.

    The message is one line that names the problem; the CLI prints it and exits with 2.
    """
