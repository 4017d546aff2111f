"""Simulated scenes as a scan source (like a recording) and as files on disk."""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path
from typing import Iterator

from people_tracker.models.scenario import ScenarioError, build_simulation, load_scenario
from people_tracker.tracker.errors import InputError
from people_tracker.tracker.io.atomic import atomic_output, check_writable
from people_tracker.tracker.io.bag_writer import BagWriter
from people_tracker.tracker.io.recording import ScanRecord

DEFAULT_SCENE = "crossing"


def _load(scenario: str, seed: int | None, people: int | None, duration: float | None, laser: str | None = None,
          resolution_deg: float | None = None):
    try:
        spec = load_scenario(scenario)
        if duration is not None:
            spec = {**spec, "duration_s": duration}
        if resolution_deg is not None:  # the same laser with another angular step (degrees)
            if laser is None:
                spec = {**spec, "laser": {**(spec.get("laser") or {}), "resolution_deg": resolution_deg}}
            elif isinstance(spec.get("lasers"), dict) and isinstance(spec["lasers"].get(laser), dict):
                spec = {**spec, "lasers": {**spec["lasers"], laser: {**spec["lasers"][laser],
                                                                     "resolution_deg": resolution_deg}}}
        return build_simulation(spec, seed=seed, crowd_count=people, laser=laser)
    except ScenarioError as exc:
        raise InputError(str(exc)) from None


class SimulatedSource:
    """A scenario run in memory, read like a :class:`~people_tracker.tracker.io.recording.Recording`.

    The sensor pose of each scan is the odometry's (drift included) composed with the mount,
    as a recording's would be; None when the scene's recording has no odometry.
    """

    def __init__(self, scenario: str = DEFAULT_SCENE, seed: int | None = None, people: int | None = None,
                 duration: float | None = None, laser: str | None = None,
                 resolution_deg: float | None = None) -> None:
        self.sim, self.scan_count = _load(scenario, seed, people, duration, laser, resolution_deg)
        self.path = f"built-in scene '{scenario}'"
        self.topic = "/scan"
        self.laser_frame = self.sim.laser.frame_id
        self.n_beams = self.sim.laser.n_beams
        self.resolution = abs(self.sim.laser.angle_increment)
        self.odometry = "simulated odometry + mount" if self.sim.has_odometry else None
        self.fixed_frame = "odom" if self.sim.has_odometry else self.laser_frame
        self.truths = []  # the Truth of every scan produced so far

    def __enter__(self) -> "SimulatedSource":
        return self

    def __exit__(self, *exc) -> None:
        pass

    def scans(self) -> Iterator[ScanRecord]:
        for index in range(self.scan_count):
            step = self.sim.step()
            self.truths.append(step.truth)
            bag_time = int(round(step.scan.stamp * 1e9))
            if not self.sim.has_odometry:
                yield ScanRecord(index, bag_time, step.scan, None, None, None)
                continue
            last = step.odom_pose_last_beam @ self.sim.mount if step.odom_pose_last_beam is not None else None
            yield ScanRecord(index, bag_time, step.scan, step.odom_pose @ self.sim.mount, None, last)


def simulate_to_bag(scenario: str, output: str | Path, seed: int | None = None, people: int | None = None,
                    duration: float | None = None, fmt: str = "mcap", progress=None,
                    laser: str | None = None) -> tuple[Path, Path, int, int, bool]:
    """Render a scenario to a recording at ``output`` and its ground truth at ``output.gt.csv``.

    The recording holds ``/scan``, ``/odom`` (``odom`` → ``base_link``), ``/tf`` (the same)
    and ``/tf_static`` (``base_link`` → laser); no ``/odom`` and ``/tf`` when the scene says
    ``odometry: false``. Ground truth has one row per person visible by Leigh's rule per scan,
    in the sensor frame, ``target`` 1 for the person the robot follows. Both files appear
    complete or not at all.

    Returns (bag path, ground truth path, scans, ground-truth rows, whether odometry was written).
    """
    out = Path(output)
    gt_path = Path(f"{out}.gt.csv")
    if out.exists():
        raise InputError(f"output '{out}' exists already")
    check_writable(out)
    sim, n_scans = _load(scenario, seed, people, duration, laser)
    parent = out.parent if str(out.parent) else Path(".")
    tmp_dir = Path(tempfile.mkdtemp(prefix=f".{out.name}.", dir=parent))
    tmp_bag = tmp_dir / out.name
    rows = 0
    try:
        with atomic_output(gt_path) as gt, BagWriter(tmp_bag, fmt) as writer:
            gt.write("scan_index,person_id,x,y,target\n")
            frame = sim.laser.frame_id
            writer.write_tf(sim.t0, [("base_link", frame, sim.mount)], static=True)
            for index in range(n_scans):
                step = sim.step()
                for sample in step.odometry if sim.has_odometry else ():
                    writer.write_odometry("/odom", sample.stamp, "odom", "base_link", sample.pose,
                                          (sample.v, 0.0, sample.omega))
                    writer.write_tf(sample.stamp, [("odom", "base_link", sample.pose)])
                # a driver publishes a scan once its sweep is over
                sweep = step.scan.time_increment * (step.scan.n_beams - 1)
                writer.write_scan("/scan", step.scan, bag_time=step.scan.stamp + sweep, scan_time=sim.laser.period)
                tr = step.truth
                for pid, (x, y) in zip(tr.person_id[tr.visible], tr.torso_sensor[tr.visible]):
                    gt.write(f"{index},{pid},{x:.4f},{y:.4f},{int(pid == sim.target_id)}\n")
                    rows += 1
                if progress is not None:
                    progress(1)
        os.replace(tmp_bag, out)
    except BaseException:
        if gt_path.exists() and not out.exists():
            gt_path.unlink()
        raise
    finally:
        shutil.rmtree(tmp_dir, ignore_errors=True)
    return out, gt_path, n_scans, rows, sim.has_odometry
