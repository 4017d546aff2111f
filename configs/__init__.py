"""Shipped YAML configuration: ``default.yaml`` and the simulator's ``scenarios/``.

Read them with :func:`importlib.resources.files` (see :mod:`people_tracker.tracker.config`).
"""
