"""Per-reading labels: the paper's sets A, M, O, N, plus readings that are not valid."""

INVALID = 0  # not a valid reading (nan, inf, 0, outside the range limits)
STATIC = 1  # A: the same stationary surface is seen in the other scan
MOVING = 2  # M: a moving object, not occluded by the other scan
OCCLUDED = 3  # O: occluded by, or revealed by, the other scan's object
OUT_OF_VIEW = 4  # N: out of the other scan's view

NAMES = {INVALID: "invalid", STATIC: "A", MOVING: "M", OCCLUDED: "O", OUT_OF_VIEW: "N"}
