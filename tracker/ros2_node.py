"""The live ROS 2 node (``people-tracker ros2``) and a recording player (``people-tracker replay``).

The only module that imports rclpy (the ``[ros2]`` extra: ``ros-rclpy`` and the message
packages are wheels on the package index; no ROS installation is needed).

The node subscribes ``sensor_msgs/LaserScan`` (sensor-data QoS) and, unless told not to,
``nav_msgs/Odometry``. The sensor pose of a scan is odometry ∘ mount, interpolated at its
first and last beam exactly as the offline reader does (``tracker.io.odometry.PoseSeries``),
waiting at most ``odometry.max_wait_s`` for odometry that covers the sweep (once any
odometry has arrived at all). Callbacks only queue messages; a worker thread tracks, so the
executor is never blocked; when tracking falls behind, the oldest queued scans are dropped
(said at most once a second). For every processed scan, stamped with the scan's stamp, it
publishes ``people`` (``geometry_msgs/PoseArray`` in the fixed frame, heading along the
velocity), ``people_markers`` (``visualization_msgs/MarkerArray``: position, id, 2σ
ellipse, velocity arrow, the target highlighted; markers of ended tracks deleted),
``people_target`` (``geometry_msgs/PoseStamped``, while a target is locked and its track is
updated: not while it coasts) and, when
asked, ``legs`` (``PoseArray``, leg candidates the leg model finds likely).
"""

from __future__ import annotations

import gc
import logging
import math
import signal
import threading
import time
from collections import deque
from dataclasses import dataclass

import numpy as np

from people_tracker.models.pose import Pose2D
from people_tracker.tracker.errors import InputError, require

log = logging.getLogger("people-tracker")

NO_SCAN_WARN_S = 2.0  # s: a silence this long on the scan topic is worth one warning


@dataclass
class NodeOptions:
    """What ``people-tracker ros2`` was asked (each is also a ROS parameter of the node)."""

    scan_topic: str = "/scan"
    odom_topic: str = "/odom"  # "" : no odometry
    mount: tuple[float, float, float] = (0.0, 0.0, 0.0)  # base frame -> laser: x, y (m), yaw (rad)
    fixed_frame: str = "odom"
    follow: str = ""  # "", "auto" or a track id
    legs: bool = False
    queue: int = 10  # scans waiting to be tracked before the oldest is dropped


def _quaternion(yaw: float):
    from geometry_msgs.msg import Quaternion
    return Quaternion(x=0.0, y=0.0, z=math.sin(0.5 * yaw), w=math.cos(0.5 * yaw))


def _percentile_ms(values: list[float], q: float) -> float:
    return float(np.percentile(np.array(values) * 1e3, q)) if values else float("nan")


class _Pending:
    __slots__ = ("msg", "received", "index", "_decoded")

    def __init__(self, msg, received: float, index: int) -> None:
        self.msg, self.received, self.index = msg, received, index
        self._decoded = None

    def decoded(self):
        """The message's scan, or None and why not (decoded once, in the worker)."""
        if self._decoded is None:
            from people_tracker.tracker.io.recording import decode_scan
            self._decoded = decode_scan(lambda: self.msg)
        return self._decoded



def _declare_parameters(node, options: NodeOptions) -> dict:
    """The node's options as ROS parameters (a launch file or --ros-args -p name:=value sets them)."""
    return {
        "scan_topic": node.declare_parameter("scan_topic", options.scan_topic).value,
        "odom_topic": node.declare_parameter("odom_topic", options.odom_topic).value,
        "mount": list(node.declare_parameter("mount", [float(options.mount[0]), float(options.mount[1]),
                                                          math.degrees(options.mount[2])]).value),
        "fixed_frame": node.declare_parameter("fixed_frame", options.fixed_frame).value,
        "follow": node.declare_parameter("follow", options.follow).value,
        "legs": node.declare_parameter("legs", options.legs).value,
        "queue": node.declare_parameter("queue", options.queue).value,
    }


def run_node(options: NodeOptions, config, ros_args: list[str] | None = None) -> int:
    """Run the node until SIGINT (or the context shuts down); returns the exit status 0."""
    rclpy = require("rclpy", "ros2", "people-tracker ros2 (the ROS 2 node)")
    from geometry_msgs.msg import Point, Pose, PoseArray, PoseStamped, Vector3
    from nav_msgs.msg import Odometry
    from rclpy.executors import ExternalShutdownException
    from rclpy.node import Node
    from rclpy.qos import QoSProfile, qos_profile_sensor_data
    from sensor_msgs.msg import LaserScan
    from std_msgs.msg import ColorRGBA
    from visualization_msgs.msg import Marker, MarkerArray

    from people_tracker.detection.deskew import sweep_duration
    from people_tracker.tracker.io.bag import stamp_seconds
    from people_tracker.tracker.io.odometry import PoseSeries, pose_from_msg
    from people_tracker.tracker.people_tracker import PeopleTracker, warm_up_kernels
    from people_tracker.tracker.scan_checks import ScanChecker

    rclpy.init(args=ros_args)
    node = Node("people_tracker")
    from rclpy.exceptions import NameValidationException, ParameterException

    try:
        p = _declare_parameters(node, options)
    except ParameterException as exc:  # a value of the wrong type (-p legs:=maybe): a bad configuration
        raise InputError(f"ROS parameter: {' '.join(str(exc).split())}") from None
    if not isinstance(p["queue"], int) or isinstance(p["queue"], bool) or p["queue"] < 1:
        raise InputError(f"parameter 'queue' must be a whole number of scans, 1 or more, got {p['queue']!r}")
    if len(p["mount"]) != 3:
        raise InputError("parameter 'mount' must be [x, y, yaw_deg]")
    mount = Pose2D(float(p["mount"][0]), float(p["mount"][1]), math.radians(float(p["mount"][2])))
    follow = None
    if p["follow"]:
        if p["follow"] != "auto" and not str(p["follow"]).isdigit():
            raise InputError(f"--follow takes auto or a track id, got '{p['follow']}'")
        follow = p["follow"] if p["follow"] == "auto" else int(p["follow"])
    tracker = PeopleTracker.from_config(config, follow)
    # the compiled kernels loaded (or, the first time on this machine, compiled) before the
    # first scan comes: loading them on it would queue scans and drop some
    warm_s = warm_up_kernels(config)
    if warm_s > 2.0:
        log.info("compiled the tracker's kernels in %.0f s (once on this machine; cached from now on)", warm_s)
    # what start-up made (the modules, the kernels, the leg model) lives to the end: out of
    # the cyclic collector's sight, its full collections no longer stall a scan (~7 ms each)
    gc.freeze()
    checker = ScanChecker(config.scan_checks.stamp_jump_periods, config.scan_checks.beam_count_confirm)
    odo = config.odometry
    series = PoseSeries(odo.max_interpolation_gap_s, odo.max_extrapolation_s)
    lock = threading.Condition()
    pending: deque[_Pending] = deque()
    state = {"index": 0, "dropped": 0, "last_drop_warn": -math.inf, "last_scan": None, "silent_warned": False,
             "stop": False, "processed": 0}
    latencies: list[float] = []
    work_times: list[float] = []  # s: from taking the scan off the queue to people published (no waiting)
    reliable = QoSProfile(depth=50)
    pub_people = node.create_publisher(PoseArray, "people", reliable)
    pub_markers = node.create_publisher(MarkerArray, "people_markers", reliable)
    pub_target = node.create_publisher(PoseStamped, "people_target", reliable)
    pub_legs = node.create_publisher(PoseArray, "legs", reliable) if p["legs"] else None
    shown: set[int] = set()
    fixed = p["fixed_frame"]
    min_leg = config.standing.min_leg_probability

    def on_scan(msg) -> None:
        now = time.perf_counter()
        with lock:
            state["last_scan"], state["silent_warned"] = now, False
            if len(pending) >= p["queue"]:
                pending.popleft()
                state["dropped"] += 1
                if now - state["last_drop_warn"] >= 1.0:
                    state["last_drop_warn"] = now
                    log.warning("tracking falls behind the scans: dropped the oldest (%d so far)", state["dropped"])
            pending.append(_Pending(msg, now, state["index"]))
            state["index"] += 1
            lock.notify()

    def on_odom(msg) -> None:
        stamp = stamp_seconds(msg.header.stamp)
        pose = pose_from_msg(msg.pose.pose.position, msg.pose.pose.orientation)[0]
        with lock:
            series.add(stamp, pose)  # a sample that goes back in time is dropped, as offline
            lock.notify()

    def on_timer() -> None:
        with lock:
            last = state["last_scan"]
            if last is not None and not state["silent_warned"] and time.perf_counter() - last > NO_SCAN_WARN_S:
                state["silent_warned"] = True
                log.warning("no scan on %s for %.0f s", p["scan_topic"], NO_SCAN_WARN_S)

    try:
        # best effort, as a laser driver publishes, but holding as many scans as the queue:
        # the sensor-data profile's 5 lost scans silently whenever the callback waited
        # (a kernel loading at the start) instead of in the queue, which says so
        sensor = qos_profile_sensor_data
        scan_qos = QoSProfile(history=sensor.history, depth=max(int(p["queue"]), sensor.depth),
                              reliability=sensor.reliability, durability=sensor.durability)
        node.create_subscription(LaserScan, p["scan_topic"], on_scan, scan_qos)
        if p["odom_topic"]:
            node.create_subscription(Odometry, p["odom_topic"], on_odom, QoSProfile(depth=200))
    except NameValidationException as exc:  # --scan-topic "front scan"
        raise InputError(f"topic name: {' '.join(str(exc).split())}") from None
    node.create_timer(0.5, on_timer)

    def header(stamp_msg, frame: str):
        from std_msgs.msg import Header
        return Header(stamp=stamp_msg, frame_id=frame)

    def markers(stamp_msg, tracks) -> MarkerArray:
        out = MarkerArray()
        now_ids = set()
        for t in tracks:
            now_ids.add(t.track_id)
            colour = ColorRGBA(r=1.0, g=0.3, b=0.1, a=1.0) if t.target else ColorRGBA(r=0.1, g=0.6, b=1.0, a=0.9)
            body = Marker(header=header(stamp_msg, fixed), ns="person", id=t.track_id, type=Marker.CYLINDER,
                          action=Marker.ADD)
            body.pose = Pose(position=Point(x=t.x, y=t.y, z=0.9), orientation=_quaternion(0.0))
            body.scale = Vector3(x=0.4, y=0.4, z=1.8)
            body.color = colour
            label = Marker(header=header(stamp_msg, fixed), ns="id", id=t.track_id, type=Marker.TEXT_VIEW_FACING,
                           action=Marker.ADD, text=str(t.track_id) + (" (target)" if t.target else ""))
            label.pose = Pose(position=Point(x=t.x, y=t.y, z=2.0), orientation=_quaternion(0.0))
            label.scale = Vector3(x=0.0, y=0.0, z=0.3)
            label.color = ColorRGBA(r=1.0, g=1.0, b=1.0, a=1.0)
            # 2σ ellipse of the position: a flat cylinder along the covariance's axes
            (a, b), (_, c) = t.position_cov
            w, v = np.linalg.eigh(np.array([[a, b], [b, c]]))
            ell = Marker(header=header(stamp_msg, fixed), ns="uncertainty", id=t.track_id, type=Marker.CYLINDER,
                         action=Marker.ADD)
            ell.pose = Pose(position=Point(x=t.x, y=t.y, z=0.01),
                            orientation=_quaternion(math.atan2(v[1, 1], v[0, 1])))
            ell.scale = Vector3(x=float(4.0 * math.sqrt(max(w[1], 1e-6))), y=float(4.0 * math.sqrt(max(w[0], 1e-6))),
                                z=0.02)
            ell.color = ColorRGBA(r=colour.r, g=colour.g, b=colour.b, a=0.3)
            arrow = Marker(header=header(stamp_msg, fixed), ns="velocity", id=t.track_id, type=Marker.ARROW,
                           action=Marker.ADD)
            arrow.points = [Point(x=t.x, y=t.y, z=1.0), Point(x=t.x + t.vx, y=t.y + t.vy, z=1.0)]
            arrow.scale = Vector3(x=0.05, y=0.1, z=0.1)
            arrow.color = colour
            out.markers += [body, label, ell, arrow]
        for gone in shown - now_ids:
            for ns in ("person", "id", "uncertainty", "velocity"):
                out.markers.append(Marker(header=header(stamp_msg, fixed), ns=ns, id=gone, action=Marker.DELETE))
        shown.clear()
        shown.update(now_ids)
        return out

    def process(item: _Pending) -> None:
        started = time.perf_counter()
        msg = item.msg
        scan, problem = item.decoded()
        pose = pose_last = None
        if scan is not None:
            with lock:
                base = series.at(scan.stamp)
                sweep = sweep_duration(scan)
                base_last = series.at(scan.stamp + sweep) if base is not None and sweep > 0 else None
                series.prune(scan.stamp - 5.0)
            pose = None if base is None else base @ mount
            pose_last = None if base_last is None else base_last @ mount
        verdict = checker.check(scan, problem)
        if verdict.reason:
            log.warning("scan %d %s", item.index, verdict.reason)
        if not verdict.use:
            return
        if verdict.restart:
            tracker.reset()
        tracks = tracker.step(scan, pose, pose_last)
        people = PoseArray(header=header(msg.header.stamp, fixed))
        for t in tracks:
            yaw = math.atan2(t.vy, t.vx) if math.hypot(t.vx, t.vy) > 1e-6 else 0.0
            people.poses.append(Pose(position=Point(x=t.x, y=t.y, z=0.0), orientation=_quaternion(yaw)))
        pub_people.publish(people)
        published = time.perf_counter()
        latencies.append(published - item.received)
        work_times.append(published - started)
        pub_markers.publish(markers(msg.header.stamp, tracks))
        target = next((t for t in tracks if t.target), None)
        if target is not None:
            yaw = math.atan2(target.vy, target.vx) if math.hypot(target.vx, target.vy) > 1e-6 else 0.0
            pub_target.publish(PoseStamped(header=header(msg.header.stamp, fixed),
                                           pose=Pose(position=Point(x=target.x, y=target.y, z=0.0),
                                                     orientation=_quaternion(yaw))))
        if pub_legs is not None:
            last = tracker.last
            legs = PoseArray(header=header(msg.header.stamp, fixed))
            if last.legs is not None and len(last.legs.xy):
                xy = last.pose.transform_points(last.legs.xy)[last.leg_scores >= min_leg]
                legs.poses = [Pose(position=Point(x=float(x), y=float(y), z=0.0), orientation=_quaternion(0.0))
                              for x, y in xy]
            pub_legs.publish(legs)
        state["processed"] += 1

    def ready(item: _Pending) -> bool:
        """Odometry covers the sweep, or none has come at all, or it waited long enough."""
        scan = item.decoded()[0]
        if len(series) == 0 or scan is None:
            return True
        return series.newest >= scan.stamp + sweep_duration(scan) or time.perf_counter() - item.received > odo.max_wait_s

    def worker() -> None:
        while True:
            with lock:
                while not state["stop"] and not (pending and ready(pending[0])):
                    lock.wait(timeout=0.02)
                if state["stop"] and not pending:
                    return
                if state["stop"] and not ready(pending[0]):
                    return
                item = pending.popleft()
            try:
                process(item)
            except Exception as exc:  # a scan the tracker cannot take must not end the node
                log.warning("scan %d could not be tracked: %s: %s", item.index, type(exc).__name__,
                            " ".join(str(exc).split())[:200])

    thread = threading.Thread(target=worker, name="people-tracker", daemon=True)
    thread.start()
    print(f"people-tracker ros2: {p['scan_topic']} -> people, people_markers, people_target"
          + (", legs" if pub_legs else "") + f" (frame {fixed}; odometry: "
          + (f"{p['odom_topic']} + mount {mount.x:g} {mount.y:g} {math.degrees(mount.yaw):g}°" if p["odom_topic"]
             else "none") + ")", flush=True)
    interrupted = threading.Event()

    def on_sigint(signum, frame) -> None:
        interrupted.set()
        if rclpy.ok():
            rclpy.try_shutdown()

    signal.signal(signal.SIGINT, on_sigint)
    signal.signal(signal.SIGTERM, on_sigint)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        with lock:
            state["stop"] = True
            pending.clear()
            lock.notify()
        thread.join(timeout=0.5)
        node.destroy_node()
        rclpy.try_shutdown()
    timing = (f"latency (scan received -> people published) p50 {_percentile_ms(latencies, 50):.2f} ms, "
              f"p99 {_percentile_ms(latencies, 99):.2f} ms; of it tracking the scan p50 "
              f"{_percentile_ms(work_times, 50):.2f} ms, p99 {_percentile_ms(work_times, 99):.2f} ms"
              if latencies else "no scan arrived")
    print(f"people-tracker ros2: {state['processed']} scans tracked, {state['dropped']} dropped; {timing}", flush=True)
    return 0


def _ros_scan(msg, LaserScan, Header, Time):
    out = LaserScan()
    out.header = Header(stamp=Time(sec=int(msg.header.stamp.sec), nanosec=int(msg.header.stamp.nanosec)),
                        frame_id=str(msg.header.frame_id))
    for name in ("angle_min", "angle_max", "angle_increment", "time_increment", "scan_time", "range_min", "range_max"):
        setattr(out, name, float(getattr(msg, name)))
    out.ranges = np.asarray(msg.ranges, dtype=np.float32).tolist()
    out.intensities = np.asarray(getattr(msg, "intensities", []), dtype=np.float32).tolist()
    return out


def _ros_odom(msg, Odometry, Header, Time):
    out = Odometry()
    out.header = Header(stamp=Time(sec=int(msg.header.stamp.sec), nanosec=int(msg.header.stamp.nanosec)),
                        frame_id=str(msg.header.frame_id))
    out.child_frame_id = str(msg.child_frame_id)
    p, q = msg.pose.pose.position, msg.pose.pose.orientation
    out.pose.pose.position.x, out.pose.pose.position.y, out.pose.pose.position.z = float(p.x), float(p.y), float(p.z)
    o = out.pose.pose.orientation
    o.x, o.y, o.z, o.w = float(q.x), float(q.y), float(q.z), float(q.w)
    tw = msg.twist.twist
    out.twist.twist.linear.x, out.twist.twist.linear.y = float(tw.linear.x), float(tw.linear.y)
    out.twist.twist.angular.z = float(tw.angular.z)
    return out


def replay(path: str, topic: str | None, rate: float, config, wait_s: float = 5.0,
           ros_args: list[str] | None = None) -> int:
    """Publish a recording's scans (and its odometry topic) on ROS 2 at ``rate`` times their
    recorded pace; print the static mount found, as the node's ``--mount``."""
    rclpy = require("rclpy", "ros2", "people-tracker replay")
    from builtin_interfaces.msg import Time
    from nav_msgs.msg import Odometry
    from rclpy.node import Node
    from rclpy.qos import QoSProfile
    from sensor_msgs.msg import LaserScan
    from std_msgs.msg import Header

    from people_tracker.tracker.io.bag import LASER_SCAN, ODOMETRY
    from people_tracker.tracker.io.odometry import OdomTopicSource
    from people_tracker.tracker.io.recording import Recording

    if not (rate > 0 and math.isfinite(rate)):
        raise InputError(f"--rate must be a positive number, got {rate!r}")
    if not (wait_s >= 0 and math.isfinite(wait_s)):
        raise InputError(f"--wait must be 0 or more seconds, got {wait_s!r}")
    with Recording(path, topic, config.odometry) as rec:
        source = rec.pose_source
        odom_conns = list(source.connections) if isinstance(source, OdomTopicSource) else []
        scan_topic = rec.topic
        odom_topic = odom_conns[0].topic if odom_conns else ""
        if isinstance(source, OdomTopicSource):
            m = source.mount
            print(f"mount: --mount {m.x:.6g} {m.y:.6g} {math.degrees(m.yaw):.6g}  (odometry {odom_topic}, "
                  f"fixed frame {source.fixed_frame})", flush=True)
        else:
            print(f"no odometry topic in the recording ({rec.odometry}): run the node with --no-odom", flush=True)
        rclpy.init(args=ros_args)
        node = Node("people_tracker_replay")
        qos = QoSProfile(depth=1000)
        pub_scan = node.create_publisher(LaserScan, scan_topic, qos)
        pub_odom = node.create_publisher(Odometry, odom_topic, qos) if odom_topic else None
        deadline = time.monotonic() + wait_s
        reader = rec._reader
        scan_ids = {c.id for c in rec._scan_conns}
        start_wall = first_bag = None
        n_scans = n_odom = 0
        interrupted = False
        try:
            while pub_scan.get_subscription_count() == 0 and time.monotonic() < deadline and rclpy.ok():
                time.sleep(0.05)
            if pub_scan.get_subscription_count():
                time.sleep(0.5)  # the subscriber's side of the match settles too: best-effort scans sent before are lost
            for conn, bag_time, raw in reader.messages(connections=list(rec._scan_conns) + odom_conns):
                if not rclpy.ok():  # SIGTERM (rclpy shut the context down): stop, as for Ctrl-C
                    interrupted = True
                    break
                if start_wall is None:
                    start_wall, first_bag = time.monotonic(), bag_time
                due = start_wall + (bag_time - first_bag) * 1e-9 / rate
                delay = due - time.monotonic()
                if delay > 0:
                    time.sleep(delay)
                try:
                    if conn.id in scan_ids:
                        pub_scan.publish(_ros_scan(reader.deserialize(raw, LASER_SCAN), LaserScan, Header, Time))
                        n_scans += 1
                    elif pub_odom is not None:
                        pub_odom.publish(_ros_odom(reader.deserialize(raw, ODOMETRY), Odometry, Header, Time))
                        n_odom += 1
                except Exception as exc:
                    if not rclpy.ok():  # shut down while it slept: stopped, not a bad message
                        interrupted = True
                        break
                    log.warning("a message on %s could not be republished: %s", conn.topic,
                                " ".join(str(exc).split())[:160])
        except KeyboardInterrupt:
            interrupted = True
        finally:
            time.sleep(0.2)  # let the last messages leave
            node.destroy_node()
            rclpy.try_shutdown()
    print(("stopped: " if interrupted else "") + f"replayed {n_scans} scans on {scan_topic}"
          + (f" and {n_odom} odometry messages on {odom_topic}" if odom_topic else "") + f" at {rate:g}x", flush=True)
    return 130 if interrupted else 0


__all__ = ["NodeOptions", "replay", "run_node"]
