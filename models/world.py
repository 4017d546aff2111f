"""The static world of the simulator: walls (line segments) and round pillars, in metres."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True, eq=False)
class World:
    """Static geometry in the world frame.

    Attributes
    ----------
    segments : ndarray, shape (m, 2, 2)
        Wall segments, each as two end points (x, y), metres.
    circles : ndarray, shape (k, 3)
        Round obstacles (pillars, bins) as centre x, y and radius, metres.
    """

    segments: np.ndarray = field(default_factory=lambda: np.zeros((0, 2, 2)))
    circles: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))

    def __post_init__(self) -> None:
        seg = np.asarray(self.segments, dtype=float).reshape(-1, 2, 2)
        cir = np.asarray(self.circles, dtype=float).reshape(-1, 3)
        seg.setflags(write=False)
        cir.setflags(write=False)
        object.__setattr__(self, "segments", seg)
        object.__setattr__(self, "circles", cir)


def box_segments(x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
    """The four sides of an axis-aligned rectangle, shape (4, 2, 2)."""
    c = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=float)
    return np.stack([c, np.roll(c, -1, axis=0)], axis=1)


def build_world(spec: dict | None) -> World:
    """A world from a scenario's ``world`` mapping.

    Keys (all optional): ``room: [x0, y0, x1, y1]`` (four walls), ``walls: [[x0, y0, x1, y1], …]``,
    ``boxes: [[x0, y0, x1, y1], …]`` (furniture), ``pillars: [[x, y, r], …]``; metres.
    """
    spec = spec or {}
    parts = []
    if "room" in spec:
        parts.append(box_segments(*spec["room"]))
    for w in spec.get("walls", []):
        parts.append(np.asarray(w, dtype=float).reshape(1, 2, 2))
    for b in spec.get("boxes", []):
        parts.append(box_segments(*b))
    segments = np.concatenate(parts) if parts else np.zeros((0, 2, 2))
    circles = np.asarray(spec.get("pillars", []), dtype=float).reshape(-1, 3)
    return World(segments, circles)
