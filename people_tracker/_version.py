"""The package version (read by setuptools at build time and by ``--version``)."""

__version__ = "0.2.0"
