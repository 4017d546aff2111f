"""Shipped YAML configuration: ``default.yaml``, other named configurations beside it, and
the simulator's ``scenarios/``; read through :mod:`importlib.resources`, so a plain wheel
install finds them.

A scenario or ``--config`` argument is a shipped name unless it ends in ``.yaml``/``.yml``
or holds a path separator: a folder in the working directory that happens to share a
scenario's name (the output of ``people-tracker simulate crossing --output crossing``)
does not hide the shipped scene.
"""

from __future__ import annotations

import os
from importlib import resources
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # pragma: no cover
    from importlib.abc import Traversable


def names_a_file(arg: str | os.PathLike) -> bool:
    """Whether a scenario or configuration argument is a file path rather than a shipped name."""
    s = os.fspath(arg)
    return s.endswith((".yaml", ".yml")) or "/" in s or os.sep in s or bool(os.altsep and os.altsep in s)


def shipped_names(folder: str = "") -> list[str]:
    """Names of the YAML files shipped in ``folder`` (``""``: the configurations, ``"scenarios"``)."""
    root = resources.files(__name__)
    root = root.joinpath(folder) if folder else root
    return sorted(p.name[:-5] for p in root.iterdir() if p.name.endswith(".yaml"))


def shipped_file(name: str, folder: str = "") -> Traversable | None:
    """The shipped ``name.yaml`` in ``folder``, or None when there is none."""
    root = resources.files(__name__)
    f = (root.joinpath(folder) if folder else root).joinpath(f"{name}.yaml")
    return f if f.is_file() else None
