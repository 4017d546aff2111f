"""The one error type that the command line turns into a single line and exit status 2."""


class InputError(Exception):
    """A bad input file or configuration: missing, empty, corrupt, wrong topic, bad value.

    The message is one line that names the problem; the CLI prints it and exits with 2.
    """


def require(module: str, extra: str, feature: str):
    """Import ``module`` for ``feature``, or say in one line which extra installs it.

    Returns the module; raises :class:`InputError` (exit status 2) when it is missing.
    """
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise InputError(f"{feature} needs the [{extra}] extra: pip install 'people-tracker[{extra}]'") from None
