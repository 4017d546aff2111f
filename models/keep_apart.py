"""People do not walk through each other: simulated walkers step aside.

Crowd members and passers-by follow random or scripted paths drawn without regard for anyone
else, so left alone two of them (or one of them and the followed person) would pass through
each other, their legs overlapping, which no real pair of bodies does; and through pillars
and trees. :func:`keep_apart` gives each such walker a *detour*: a sideways offset from
their path, in the world frame, that keeps their torso at least ``gap_m`` from everyone
placed before them, and ``gap_m / 2`` (about a body's half width) from the edge of round
obstacles (pillars, trees, table legs). They start to step aside ``lookahead_s`` before
they would come too close, at no more than ``sidestep_mps`` across their walking direction
(to the right when the meeting is head-on), and drift back to their path at ``return_mps``
once clear. ``bounds`` (an area they stay in, such as the crowd's) can stop a detour short,
so a pair may still come closer than ``gap_m`` where a wall leaves no room; the walkers
placed first (scripted people, visitors) never step aside.

Units: metres, seconds, world frame.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from people_tracker.models.person import Walker

#: metres between two people's torso centres: about a shoulder width, so the nearest legs of
#: two people passing shoulder to shoulder are still a hand apart
GAP_M = 0.45


def keep_apart(fixed: list[Walker], yielding: list[Walker], duration_s: float, gap_m: float = GAP_M,
               dt_s: float = 0.1, lookahead_s: float = 1.0, sidestep_mps: float = 0.8, return_mps: float = 0.3,
               bounds: dict[int, tuple[float, float, float, float]] | None = None,
               obstacles: np.ndarray | None = None, visitors: list[Walker] | None = None,
               robot: Callable[[np.ndarray], np.ndarray] | None = None, robot_radius_m: float = 0.0) -> None:
    """Set ``detour`` on each of ``yielding`` (in order) so they keep ``gap_m`` from ``fixed``,
    from ``visitors`` and from the yielding walkers before them, and half of it from the edge
    of each round obstacle in ``obstacles`` (x, y, radius; m, world frame: pillars, trees,
    table legs). ``visitors`` (people who walk to a place, stand there a while and leave, as
    in a waiting room) step aside for everyone but the yielding, before them in the list or
    after, while they walk, and hold their place while they stand: whoever walks past
    someone standing makes way. ``robot`` gives the robot base's place (m, world frame) at
    each of an array of times (s): everyone keeps half of ``gap_m`` from its edge, a disc of
    ``robot_radius_m``, as from a round obstacle that moves (the robot drives on and makes
    way for nobody). ``bounds`` maps a walker's ``person_id`` to an area
    ``(x0, y0, x1, y1)`` their torso stays in. Walkers are changed in place."""
    visitors, bounds = list(visitors or []), bounds or {}
    if gap_m <= 0 or not (yielding or visitors):
        return
    times = np.arange(0.0, duration_s + dt_s, dt_s)
    ahead = max(1, int(round(lookahead_s / dt_s)))
    horizons = sorted({0, ahead // 2, ahead})
    obstacles = np.asarray(obstacles if obstacles is not None else np.zeros((0, 3)), dtype=float).reshape(-1, 3)
    # everyone placed so far, row by row: torso or obstacle centre (m) and velocity (m/s),
    # world frame, at each time; whether there; the gap to keep from them (m). Filled in
    # place, so that an hour's scene does not copy them all again for each walker
    rows = len(obstacles) + (robot is not None) + len(fixed) + len(visitors) + len(yielding)
    pos, vel = np.zeros((rows, len(times), 2)), np.zeros((rows, len(times), 2))
    there, gaps = np.zeros((rows, len(times)), dtype=bool), np.zeros(rows)
    pos[:len(obstacles)] = obstacles[:, None, :2]
    there[:len(obstacles)] = True
    gaps[:len(obstacles)] = obstacles[:, 2] + 0.5 * gap_m
    m = len(obstacles)

    def place(row: int, where: np.ndarray, present: np.ndarray, gap: float = gap_m) -> None:
        pos[row], there[row], gaps[row] = where, present, gap
        vel[row] = np.gradient(where, dt_s, axis=0) if len(times) > 1 else 0.0

    if robot is not None:  # a round obstacle that drives
        place(m, np.asarray(robot(times), dtype=float).reshape(len(times), 2), True, robot_radius_m + 0.5 * gap_m)
        m += 1

    def detour(w: Walker, base: np.ndarray, heading: np.ndarray, present: np.ndarray, upto: int,
               hold_when_still: bool = False) -> np.ndarray:
        """``w``'s path with the detour that keeps them clear of rows ``:upto`` (set on them)."""
        if upto:
            offsets = _sidesteps(base, heading, pos[:upto], vel[:upto], there[:upto] & present[None, :],
                                 gaps[:upto], horizons, sidestep_mps * dt_s, return_mps * dt_s,
                                 bounds.get(w.person_id), dt_s, hold_when_still)
            if offsets is not None:
                w.detour = (times, offsets)
                return base + offsets
        return base

    for w in fixed:  # they keep to their paths
        where, _, present = w.path_positions(times)
        place(m, where, present)
        m += 1
    paths = [w.path_positions(times) for w in visitors]
    first = m
    for base, _, present in paths:  # everyone's path, each replaced by its detour once it has one
        place(m, base, present)
        m += 1
    for i, (w, (base, heading, present)) in enumerate(zip(visitors, paths)):
        row = first + i
        there[row] = False  # not from themselves
        place(row, detour(w, base, heading, present, m, hold_when_still=True), present)
    for w in yielding:
        base, heading, present = w.path_positions(times)
        place(m, detour(w, base, heading, present, m), present)
        m += 1


#: metres: the farthest a detour takes a walker from their path
_MOST_M = 1.0
#: metres: how far beyond their gap to look for people and obstacles that may need avoiding
_REACH_M = _MOST_M + 0.5
#: time steps whose tables of who is close are built at once (a minute at 0.1 s)
_CHUNK_STEPS = 600
#: m/s: a path slower than this stands still (a visitor at their spot)
_STILL_MPS = 0.05


def _sidesteps(base, heading, others, others_v, others_present, gaps, horizons, step_m, back_m, box, dt_s,
               hold_when_still=False):
    """The offset (n, 2) from the path, world frame, metres, time step by time step, or None
    when nobody comes near.

    ``others`` and ``others_v`` (m, n, 2) are the others' places (m) and velocities (m/s),
    ``others_present`` (m, n) whether each is there with this walker; with
    ``hold_when_still``, wherever their path stands still (below ``_STILL_MPS``) the walker
    neither steps aside nor drifts back. Each step looks at
    where this walker and the others will be ``horizons`` steps ahead and
    steps aside across their motion relative to the other (out of the other's way), enough
    to clear each of them by their ``gaps`` (m, one per other). Plain floats: a step meets
    zero to three people, too few for array calls to pay."""
    n = len(base)
    last = n - 1
    dist = np.hypot(others[..., 0] - base[None, :, 0], others[..., 1] - base[None, :, 1])
    close = others_present & (dist < gaps[:, None] + _REACH_M)  # (m, n)
    if not close.any():
        return None
    own_v = np.gradient(base, dt_s, axis=0) if n > 1 else np.zeros_like(base)
    bx, by = base[:, 0].tolist(), base[:, 1].tolist()
    hx, hy = heading[:, 0].tolist(), heading[:, 1].tolist()
    vx, vy = own_v[:, 0].tolist(), own_v[:, 1].tolist()
    hold = ((np.hypot(own_v[:, 0], own_v[:, 1]) < _STILL_MPS) if hold_when_still else np.zeros(n, dtype=bool)).tolist()
    offsets = np.zeros((n, 2))
    ox = oy = 0.0
    order = horizons[::-1] * 4
    for k0 in range(0, n, _CHUNK_STEPS):  # the tables of who is close, a chunk of steps at a time
        k1 = min(k0 + _CHUNK_STEPS, n)
        near, where, moving = _close_tables(k0, k1, close, others, others_v, gaps, horizons)
        busy = set().union(*(t.keys() for t in near.values()))
        for k in range(k0, k1):
            if (k not in busy and ox == 0.0 and oy == 0.0) or hold[k]:
                offsets[k] = ox, oy
                continue
            size = math.hypot(ox, oy)  # drift back to the path
            keep = max(0.0, 1.0 - back_m / size) if size > 0 else 0.0
            gx, gy = ox * keep, oy * keep
            # the farthest look first, so what is closest in time has the last word; again, so a
            # step aside for one does not leave the walker on another
            for h in order:
                span = near[h].get(k)
                if span is None:
                    continue
                j = min(k + h, last)
                px, py, pg = where[h]
                qx, qy = moving[h]
                sx = sy = 0.0
                for i in range(*span):
                    gap = pg[i]
                    dx, dy = bx[j] + gx - px[i], by[j] + gy - py[i]  # from them to this walker
                    rx, ry = vx[j] - qx[i], vy[j] - qy[i]
                    speed = math.hypot(rx, ry)
                    if speed > 0.05:  # out of their way, across the motion relative to them
                        ux, uy = rx / speed, ry / speed
                        along = dx * ux + dy * uy
                        if abs(along) >= gap:
                            continue
                        ax, ay = -uy, ux
                        across = dx * ax + dy * ay
                        need = math.sqrt(gap * gap - along * along) - abs(across)
                        if need > 0:
                            if abs(across) > 1e-3:
                                side = 1.0 if across > 0 else -1.0
                            else:  # head-on: to the right of this walker's own heading
                                side = -1.0 if ax * -hy[j] + ay * hx[j] > 0 else 1.0
                            sx += need * side * ax
                            sy += need * side * ay
                    else:  # both standing, or walking side by side: straight apart
                        apart = math.hypot(dx, dy)
                        need = gap - apart
                        if need > 0:
                            ux, uy = (dx / apart, dy / apart) if apart > 1e-6 else (-hy[j], hx[j])
                            sx += need * ux
                            sy += need * uy
                gx, gy = gx + sx, gy + sy
            cx, cy = gx - ox, gy - oy
            size = math.hypot(cx, cy)
            if size > step_m:
                cx, cy = cx * step_m / size, cy * step_m / size
            ox, oy = ox + cx, oy + cy
            size = math.hypot(ox, oy)
            if size > _MOST_M:
                ox, oy = ox * _MOST_M / size, oy * _MOST_M / size
            if box is not None:
                ox = min(max(bx[k] + ox, box[0]), box[2]) - bx[k]
                oy = min(max(by[k] + oy, box[1]), box[3]) - by[k]
            offsets[k] = ox, oy
    return offsets if offsets.any() else None


def _close_tables(k0, k1, close, others, others_v, gaps, horizons):
    """Who is close at each step k of ``k0``..``k1`` - 1, h steps ahead, for each h of
    ``horizons``: ``near[h][k]`` is the range of them in the h-th lists of their positions
    and gaps (m) and velocities (m/s, world frame) at step k + h. Plain lists, which the
    step-by-step loop reads fastest; built a chunk at a time, as an hour's would hold
    millions of floats."""
    last = close.shape[1] - 1
    near, where, moving = {}, {}, {}
    for h in horizons:
        j_of = np.minimum(np.arange(k0, k1) + h, last)
        when, who = np.nonzero(close[:, j_of].T)  # sorted by step
        j = j_of[when]
        where[h] = (others[who, j, 0].tolist(), others[who, j, 1].tolist(), gaps[who].tolist())
        moving[h] = (others_v[who, j, 0].tolist(), others_v[who, j, 1].tolist())
        steps, first = np.unique(when + k0, return_index=True)
        ends = np.append(first[1:], len(when))
        near[h] = dict(zip(steps.tolist(), zip(first.tolist(), ends.tolist())))
    return near, where, moving
