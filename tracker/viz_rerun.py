"""Visualisation with rerun: every stage of the pipeline, in the world frame.

Entities (all in the world frame, metres; timelines ``scan`` (index) and ``stamp``):

* ``world/scan``: the readings coloured by their set (A static grey, M moving red,
  O occluded orange, N out of view blue);
* ``world/objects/hulls`` and ``world/objects/boxes``: moving objects' convex hulls and
  minimum rotated rectangles;
* ``world/candidates``: person candidates (pairs green, single legs yellow, blobs cyan;
  leg pairs found by shape, standing people, magenta);
* ``world/tracks`` (positions with their ids), ``world/tracks/trails``,
  ``world/tracks/covariance`` (2σ ellipses); the followed person larger;
* ``world/robot`` (the sensor's pose as an arrow) and ``world/robot/path``;
* ``world/ground_truth`` when the input has it;
* ``metrics/people`` (confirmed tracks), ``metrics/ground_truth`` and
  ``metrics/latency_ms`` per scan;
* ``world/overview``, logged once the run ends and shown at every time: each track's
  whole trajectory and the robot's path.
"""

from __future__ import annotations

import math
import os
import socket
import sys
import tempfile
import time
from collections import defaultdict, deque
from pathlib import Path

import numpy as np

import rerun as rr
import rerun.blueprint as rrb
import shapely

from people_tracker.detection.labels import MOVING, OCCLUDED, OUT_OF_VIEW, STATIC
from people_tracker.tracker.io.atomic import OutputError, publish, temp_beside
from people_tracker.tracker.sinks import Sink

VIEWER_PORT = 9876  # rerun's default
VIEWER_START_S = 10.0  # how long the spawned viewer may take to listen
FLUSH_S = 10.0  # how long closing may wait for the last data to reach the file or the viewer


def display_available() -> bool:
    """Whether a window can open here: on Linux and the BSDs an X11 or Wayland display must
    be set; macOS and Windows always have one."""
    if sys.platform.startswith(("linux", "freebsd", "openbsd", "netbsd")):
        return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    return True


def _start_viewer() -> None:
    """Start the rerun viewer as a process of its own (it outlives the run) and wait until it
    listens; if it exits first, say why in one line."""
    import subprocess

    err = tempfile.TemporaryFile()
    proc = subprocess.Popen([sys.executable, "-m", "rerun_cli", "--port", str(VIEWER_PORT), "--memory-limit", "75%"],
                            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=err, start_new_session=True)
    deadline = time.monotonic() + VIEWER_START_S
    while not _listening(VIEWER_PORT, 0.0):
        if proc.poll() is not None or time.monotonic() > deadline:
            if proc.poll() is None:
                proc.kill()
            err.seek(0)
            lines = [ln for ln in err.read().decode(errors="replace").splitlines() if ln.strip()]
            why = " ".join(lines[-1].split())[:200] if lines else f"nothing listens on port {VIEWER_PORT}"
            raise OutputError(f"the rerun viewer did not start ({why}); save the run with --rrd FILE.rrd instead")
        time.sleep(0.1)


def _listening(port: int, timeout_s: float) -> bool:
    """Whether something accepts connections on localhost ``port`` within ``timeout_s``."""
    deadline = time.monotonic() + timeout_s
    while True:
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=0.5):
                return True
        except OSError:
            if time.monotonic() >= deadline:
                return False
            time.sleep(0.1)

_SET_COLOURS = [(STATIC, "A static", (150, 150, 150)), (MOVING, "M moving", (230, 40, 40)),
                (OCCLUDED, "O occluded", (255, 160, 0)), (OUT_OF_VIEW, "N out of view", (60, 110, 255))]
_CANDIDATE_COLOURS = {"pair": (40, 200, 80), "leg": (230, 210, 40), "blob": (40, 200, 220),
                      "standing": (220, 60, 220)}
_TRAIL = 40  # scans of trail per track


def _colour(track_id: int) -> tuple[int, int, int]:
    h = (track_id * 0.618033988749895) % 1.0  # golden-ratio hues: neighbouring ids differ
    i = int(h * 6)
    f = h * 6 - i
    v, s = 0.95, 0.75
    p, q, t = v * (1 - s), v * (1 - s * f), v * (1 - s * (1 - f))
    r, g, b = [(v, t, p), (q, v, p), (p, v, t), (p, q, v), (t, p, v), (v, p, q)][i % 6]
    return int(255 * r), int(255 * g), int(255 * b)


def _ellipse(mean: np.ndarray, cov: np.ndarray, k: float = 2.0, n: int = 32) -> np.ndarray:
    w, v = np.linalg.eigh(cov)
    t = np.linspace(0, 2 * math.pi, n)
    circle = np.column_stack([np.cos(t), np.sin(t)]) * (k * np.sqrt(np.maximum(w, 0)))
    return mean + circle @ v.T


class RerunSink(Sink):
    """Logs each step to a rerun recording: saved to ``rrd`` (atomically), or sent to a viewer.

    Parameters
    ----------
    rrd : path-like, optional
        File to write; it appears only when the run ends normally.
    spawn : bool
        Open the rerun viewer and stream to it.
    name : str
        The recording's application id.
    """

    def __init__(self, rrd: str | Path | None = None, spawn: bool = False, name: str = "people-tracker") -> None:
        self.rec = rr.RecordingStream(name)
        self._target = Path(rrd) if rrd else None
        self._tmp = None
        self._trails: dict[int, deque] = defaultdict(lambda: deque(maxlen=_TRAIL))
        self._history: dict[int, list[tuple[float, float]]] = defaultdict(list)  # whole trajectories
        self._path: list[tuple[float, float]] = []
        try:  # interrupted while starting (Ctrl-C as rerun loads): the hidden file goes too
            self._start(spawn)
        except BaseException:
            self.abort()
            raise

    def _start(self, spawn: bool) -> None:
        if self._target is not None:
            fd, tmp = temp_beside(self._target)
            self._tmp = Path(tmp)
            os.close(fd)
            self.rec.save(str(self._tmp))
        elif spawn:
            self._spawn()
        self.rec.send_blueprint(rrb.Blueprint(
            rrb.Horizontal(
                rrb.Spatial2DView(origin="world", name="world (m)"),
                rrb.Vertical(rrb.TimeSeriesView(origin="metrics/people", name="people"),
                             rrb.TimeSeriesView(origin="metrics/ground_truth", name="ground truth"),
                             rrb.TimeSeriesView(origin="metrics/latency_ms", name="latency (ms)")),
                column_shares=[3, 1]),
            rrb.TimePanel(timeline="scan"), collapse_panels=True))
        self.rec.log("world/scan", rr.AnnotationContext(
            [rr.ClassDescription(info=rr.AnnotationInfo(id=i, label=lab, color=c)) for i, lab, c in _SET_COLOURS]),
            static=True)

    def scan(self, index: int, stamp: float, result, latency_s: float,
             truth_sensor: np.ndarray | None = None) -> None:
        rec = self.rec
        rec.set_time("scan", sequence=index)
        rec.set_time("stamp", timestamp=stamp)
        pose, scan = result.pose, result.scan
        labels = result.detection.labels
        valid = scan.valid
        rec.log("world/scan", rr.Points2D(pose.transform_points(scan.points[valid]),
                                           class_ids=labels[valid].astype(np.uint16), radii=0.02))
        hulls, boxes = [], []
        for o in result.detection.objects:
            pts = pose.transform_points(o.points)
            cloud = shapely.multipoints(pts)
            with np.errstate(all="ignore"):  # as in detection.objects: sub-micrometre objects
                hull = shapely.convex_hull(cloud)
                rect = shapely.minimum_rotated_rectangle(cloud)
            for geom, out in ((hull, hulls), (rect, boxes)):
                if isinstance(geom, shapely.Polygon):
                    out.append(np.asarray(geom.exterior.coords))
                elif isinstance(geom, shapely.LineString):
                    out.append(np.asarray(geom.coords))
        rec.log("world/objects/hulls", rr.LineStrips2D(hulls, colors=(230, 40, 40), radii=0.01))
        rec.log("world/objects/boxes", rr.LineStrips2D(boxes, colors=(255, 120, 120), radii=0.005))
        cands = list(result.candidates) + list(result.standing)
        rec.log("world/candidates", rr.Points2D([(c.x, c.y) for c in cands],
                                                colors=[_CANDIDATE_COLOURS.get(c.kind, (255, 255, 255)) for c in cands],
                                                radii=0.06))
        tracks = result.tracks
        for t in tracks:
            self._trails[t.track_id].append((t.x, t.y))
            self._history[t.track_id].append((t.x, t.y))
        live = {t.track_id for t in tracks}
        for tid in list(self._trails):
            if tid not in live:
                del self._trails[tid]
        rec.log("world/tracks", rr.Points2D([(t.x, t.y) for t in tracks],
                                            labels=[f"{t.track_id}{' (target)' if t.target else ''}" for t in tracks],
                                            colors=[_colour(t.track_id) for t in tracks],
                                            radii=[0.25 if t.target else 0.15 for t in tracks]))
        rec.log("world/tracks/trails", rr.LineStrips2D([np.array(self._trails[t.track_id]) for t in tracks],
                                                       colors=[_colour(t.track_id) for t in tracks], radii=0.02))
        rec.log("world/tracks/covariance", rr.LineStrips2D(
            [_ellipse(np.array([t.x, t.y]), np.array(t.position_cov)) for t in tracks],
            colors=[_colour(t.track_id) for t in tracks], radii=0.01))
        heading = np.array([math.cos(pose.yaw), math.sin(pose.yaw)]) * 0.5
        rec.log("world/robot", rr.Arrows2D(origins=[(pose.x, pose.y)], vectors=[heading], colors=(210, 210, 210)))
        self._path.append((pose.x, pose.y))
        rec.log("world/robot/path", rr.LineStrips2D([np.array(self._path)], colors=(210, 210, 210), radii=0.02))
        if truth_sensor is not None:
            rec.log("world/ground_truth", rr.Points2D(pose.transform_points(np.asarray(truth_sensor).reshape(-1, 2)),
                                                      colors=(255, 255, 255), radii=0.1))
            rec.log("metrics/ground_truth", rr.Scalars(float(len(truth_sensor))))
        rec.log("metrics/people", rr.Scalars(float(len(tracks))))
        rec.log("metrics/latency_ms", rr.Scalars(1e3 * latency_s))

    def _spawn(self) -> None:
        """Start the viewer (or use one already listening) and stream to it; fail at once,
        in one line, where none can start, rather than log into the void."""
        if not display_available():
            raise OutputError("--spawn needs a display for the rerun viewer and none is set (DISPLAY, "
                              "WAYLAND_DISPLAY); save the run with --rrd FILE.rrd and open it where there "
                              "is one with: rerun FILE.rrd")
        if not _listening(VIEWER_PORT, 0.0):
            _start_viewer()
        self.rec.connect_grpc(f"rerun+http://127.0.0.1:{VIEWER_PORT}/proxy")

    def close(self) -> None:
        ids = sorted(self._history)
        self.rec.log("world/overview/tracks", rr.LineStrips2D(
            [np.array(self._history[i]) for i in ids], colors=[_colour(i) for i in ids], radii=0.03,
            labels=[str(i) for i in ids]), static=True)
        if self._path:
            self.rec.log("world/overview/robot_path", rr.LineStrips2D([np.array(self._path)], colors=(210, 210, 210),
                                                                     radii=0.03), static=True)
        try:
            self.rec.flush(timeout_sec=FLUSH_S)
            self.rec.disconnect()
            if self._tmp is not None:
                publish(self._tmp, self._target)
                self._tmp = None
        except Exception as exc:
            self.abort()
            what = f"cannot write output '{self._target}'" if self._target else "cannot stream to the rerun viewer"
            raise OutputError(f"{what}: {' '.join(str(exc).split())[:200]}") from None

    def abort(self) -> None:
        try:
            self.rec.flush(timeout_sec=1.0)  # never wait long for a viewer that is gone
            self.rec.disconnect()
        except Exception:  # pragma: no cover - the run already failed; leave no file behind
            pass
        finally:
            if self._tmp is not None and self._tmp.exists():
                self._tmp.unlink()
                self._tmp = None
