"""people-tracker: find and follow people in 2D laser scans from a moving robot.

The API for a robot's own loop or a ROS node::

    from people_tracker import PeopleTracker, Scan, Pose2D, load_config

    tracker = PeopleTracker.from_config(load_config())
    tracks = tracker.step(scan, pose)   # confirmed people, coasting ones included

Subpackages: :mod:`people_tracker.models` (shared types, physical models, the simulator),
:mod:`people_tracker.detection` (the paper's detector), :mod:`people_tracker.tracker`
(tracking and the application around it) and :mod:`people_tracker.configs` (shipped YAML).
The names above are imported on first use, so ``import people_tracker`` and the command
line's ``--help`` stay fast.
"""

from __future__ import annotations

import os as _os
from importlib import import_module

_API = {
    "PeopleTracker": "people_tracker.tracker.people_tracker",
    "Track": "people_tracker.tracker.tracks",
    "Scan": "people_tracker.models.scan",
    "Pose2D": "people_tracker.models.pose",
    "load_config": "people_tracker.tracker.config",
    "InputError": "people_tracker.tracker.errors",
}

__all__ = sorted(_API) + ["__version__"]

# In a source checkout the subpackages sit beside this folder (pyproject.toml's package-dir maps
# tracker/ to people_tracker.tracker, and so on). When Python takes this folder from the checkout
# itself (``python -c``/``python -m people_tracker`` run in the checkout's root, which shadows an
# installed copy), the subpackages are looked up there too, so the checkout imports whole.
_checkout = _os.path.dirname(_os.path.dirname(_os.path.abspath(__file__)))
if (_os.path.isfile(_os.path.join(_checkout, "pyproject.toml"))
        and _os.path.isfile(_os.path.join(_checkout, "tracker", "people_tracker.py"))):  # never site-packages
    __path__.append(_checkout)
del _checkout


def __getattr__(name: str):
    if name == "__version__":
        from people_tracker._version import __version__ as value

        globals()[name] = value
        return value
    if name in _API:
        value = getattr(import_module(_API[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'people_tracker' has no attribute '{name}'")


def __dir__() -> list[str]:
    return __all__
