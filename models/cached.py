"""A per-instance cached attribute without the lock of Python 3.11's ``functools.cached_property``.

``functools.cached_property`` took a lock on every first access until Python 3.12 (about
0.5 µs); the tracker makes several poses and scans a scan and reads most of their cached
values once, so that lock was a measurable share of a step. This descriptor is what 3.12's
is: the value computed on the first access goes into the instance's ``__dict__`` under the
attribute's name, where later lookups find it without calling the descriptor. It works on
frozen dataclasses (it writes the ``__dict__``, not through ``__setattr__``). Like 3.12's, it
is not thread safe for the first access: two threads may both compute the (equal) value.
"""

from __future__ import annotations


class cached_property:  # noqa: N801 (named as the functools one it replaces)
    """``functools.cached_property`` as Python 3.12 has it: no lock."""

    def __init__(self, func) -> None:
        self.func = func
        self.attrname = func.__name__
        self.__doc__ = func.__doc__

    def __set_name__(self, owner, name: str) -> None:
        self.attrname = name

    def __get__(self, instance, owner=None):
        if instance is None:
            return self
        value = instance.__dict__[self.attrname] = self.func(instance)
        return value
