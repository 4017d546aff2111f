"""The live ROS 2 node, fed by `people-tracker replay` and by hand-made bad messages.

Each test runs the node in a subprocess on a ROS domain of its own; the messages it
publishes are read by a listener subprocess (as any ROS user would), so nothing here
shares rclpy state with pytest.
"""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

from tests_helpers import assert_one_line_error, cli_command

pytest.importorskip("rclpy", reason="the [ros2] extra (ros-rclpy and the message wheels) is not installed")

LISTENER = textwrap.dedent('''
    import json, sys, time, rclpy
    from rclpy.node import Node
    from visualization_msgs.msg import Marker, MarkerArray
    from geometry_msgs.msg import PoseArray
    rclpy.init()
    n = Node("test_listener")
    out = {"rows": [], "people": 0, "deleted": 0}
    def on_markers(m):
        for mk in m.markers:
            if mk.ns == "person":
                if mk.action == Marker.ADD:
                    out["rows"].append((mk.header.stamp.sec + mk.header.stamp.nanosec * 1e-9, mk.id,
                                        mk.pose.position.x, mk.pose.position.y))
                else:
                    out["deleted"] += 1
    def on_people(m):
        out["people"] += 1
    n.create_subscription(MarkerArray, "people_markers", on_markers, 1000)
    n.create_subscription(PoseArray, "people", on_people, 1000)
    print("listening", flush=True)
    while n.count_publishers("people_markers") == 0:  # the node found: nothing it says is missed
        rclpy.spin_once(n, timeout_sec=0.05)
    print("matched", flush=True)
    end = time.time() + float(sys.argv[2])  # at most this long; done once every scan's people came
    while time.time() < end and out["people"] < int(sys.argv[3]):
        rclpy.spin_once(n, timeout_sec=0.05)
    end = min(end, time.time() + 1.0)  # and the last scan's markers
    while time.time() < end:
        rclpy.spin_once(n, timeout_sec=0.05)
    json.dump(out, open(sys.argv[1], "w"))
''')


def _env(test: int) -> dict:
    """A ROS domain of the test's own: even for test 0, odd for test 1 (so two tests that run
    at once, in two pytest workers, never share one), and by the process id, so two runs of
    the suite on one machine rarely do."""
    domain = 40 + 2 * (os.getpid() % 25) + test
    return {**os.environ, "ROS_DOMAIN_ID": str(domain), "PYTHONUNBUFFERED": "1"}


def _start_node(env, *args) -> subprocess.Popen:
    proc = subprocess.Popen(cli_command() + ["ros2", *args], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    deadline = time.time() + 30
    line = proc.stdout.readline()  # the node says what it subscribed to once it runs
    assert "people-tracker ros2:" in line and time.time() < deadline, (line, proc.stderr.read() if proc.poll() else "")
    return proc


def _stop(proc: subprocess.Popen) -> tuple[int, str, str, float]:
    t0 = time.time()
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=10)
    return proc.returncode, out, err, time.time() - t0


def test_the_node_publishes_what_the_offline_run_writes(tmp_path, moving_bag):
    """873 scans replayed at 4x with their odometry: every scan tracked, none dropped (a queue
    long enough for all, so however slow the machine), and the people (ids and fixed-frame
    positions) are those of `people-tracker run --tracks`."""
    env = _env(0)
    offline = tmp_path / "offline.csv"
    assert subprocess.run(cli_command() + ["-q", "run", str(moving_bag), "--tracks", str(offline)], env=env,
                          capture_output=True, timeout=300).returncode == 0
    listener = subprocess.Popen([sys.executable, "-c", LISTENER, str(tmp_path / "heard.json"), "240", "873"], env=env,
                                stdout=subprocess.PIPE, text=True)
    assert listener.stdout.readline().strip() == "listening"
    node = _start_node(env, "--mount", "0.850326", "0.235214", "42.1014", "--queue", "1000")
    assert listener.stdout.readline().strip() == "matched"
    time.sleep(1.0)  # and the node's side of the match settled
    replay = subprocess.run(cli_command() + ["replay", str(moving_bag), "--rate", "4"], env=env, capture_output=True,
                            text=True, timeout=120)
    assert replay.returncode == 0, replay.stderr
    assert "--mount 0.850326 0.235214 42.1014" in replay.stdout and "replayed 873 scans" in replay.stdout
    listener.wait(timeout=300)  # it has heard every scan's people (or given up): the node is done
    code, out, err, took = _stop(node)
    # SIGINT: a normal shutdown, not the kill after 10 s (the margin: a 2-core machine running the
    # other tests beside it took 1.5 s or more once in three runs)
    assert code == 0 and took < 5.0, (code, took, err)
    assert "873 scans tracked, 0 dropped" in out and "p50" in out and "p99" in out and "of it tracking the scan" in out, out
    heard = json.loads((tmp_path / "heard.json").read_text())
    live = {(round(s, 6), i): (x, y) for s, i, x, y in heard["rows"]}
    with offline.open() as fh:
        rows = {(round(float(r["stamp"]), 6), int(r["track_id"])): (float(r["world_x"]), float(r["world_y"]))
                for r in csv.DictReader(fh)}
    assert rows and set(live) == set(rows)  # the same people, with the same ids, at the same scans
    err_m = max(np.hypot(live[k][0] - rows[k][0], live[k][1] - rows[k][1]) for k in rows)
    assert err_m < 1e-3, err_m
    assert heard["deleted"] > 0  # markers of ended tracks are deleted


BAD = textwrap.dedent('''
    import math, sys, time, rclpy
    from rclpy.node import Node
    from rclpy.qos import QoSProfile
    from sensor_msgs.msg import LaserScan
    from nav_msgs.msg import Odometry
    rclpy.init()
    n = Node("bad_publisher")
    scans = n.create_publisher(LaserScan, "/scan", QoSProfile(depth=100))
    odom = n.create_publisher(Odometry, "/odom", QoSProfile(depth=100))
    while scans.get_subscription_count() == 0:
        time.sleep(0.05)
    time.sleep(1.0)  # the node's side of the match settles too: best-effort scans sent before are lost
    def scan(k, ranges):
        m = LaserScan()
        m.header.stamp.sec, m.header.stamp.nanosec = 100 + k // 10, (k % 10) * 100000000
        m.header.frame_id = "laser"
        m.angle_min, m.angle_increment = -1.5, 3.0 / 360
        m.angle_max = m.angle_min + m.angle_increment * (len(ranges) - 1)
        m.range_min, m.range_max = 0.05, 20.0
        m.ranges = [float(r) for r in ranges]
        return m
    def od(t, x):
        m = Odometry()
        m.header.stamp.sec, m.header.stamp.nanosec = int(t), int(round((t % 1) * 1e9))
        m.header.frame_id, m.child_frame_id = "odom", "base_link"
        m.pose.pose.position.x = x
        m.pose.pose.orientation.w = 1.0
        return m
    for k in range(60):
        t = 100 + k * 0.1
        odom.publish(od(t, 0.01 * k if k != 30 else -5.0))  # odometry that jumps back once
        if k == 10:
            ranges = []  # empty
        elif k == 20:
            ranges = [math.nan] * 361  # all invalid
        elif 40 <= k < 42:
            ranges = [4.0] * 200  # a changed beam count, for two scans
        else:
            ranges = [4.0] * 361
        scans.publish(scan(k, ranges))
        time.sleep(0.02)
    time.sleep(1.0)
    print("sent", flush=True)
''')


def test_bad_messages_are_handled_as_the_offline_reader_handles_them(tmp_path):
    env = _env(1)
    node = _start_node(env)
    bad = subprocess.run([sys.executable, "-c", BAD], env=env, capture_output=True, text=True, timeout=60)
    assert bad.returncode == 0 and "sent" in bad.stdout, bad.stderr
    code, out, err, _ = _stop(node)
    assert code == 0, err
    assert "Traceback" not in err, err
    assert "scan 10" in err and "scan 20" in err, err  # one warning each, as `run` gives
    assert "beam" in err, err
    # 60 scans: the empty one, the all-invalid one and the two with a new beam count are skipped
    assert "56 scans tracked, 0 dropped" in out, out


@pytest.mark.parametrize("args, says", [(["--ros-args", "-p", "legs:=maybe"], "ROS parameter"),
                                        (["--ros-args", "-p", "queue:=0"], "queue"),
                                        (["--scan-topic", "front#scan"], "topic name")])
def test_a_bad_ros_parameter_or_topic_is_one_line_and_exit_2(args, says):
    proc = subprocess.run(cli_command() + ["ros2", *args], env=_env(1), capture_output=True, text=True, timeout=60)
    assert_one_line_error(proc, says)


def test_replay_refuses_a_negative_wait(negative_bag):
    proc = subprocess.run(cli_command() + ["replay", str(negative_bag), "--topic", "/rear_scan", "--wait", "-1"],
                          env=_env(1), capture_output=True, text=True, timeout=60)
    assert_one_line_error(proc, "--wait")


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_replay_stops_on_a_signal_and_says_so(negative_bag, sig):
    # 58 s of recording at its own pace: a signal after the start ends it at once, status 130,
    # with no warning about messages it could not send after ROS shut down
    proc = subprocess.Popen(cli_command() + ["replay", str(negative_bag), "--topic", "/rear_scan", "--wait", "0"],
                            env=_env(1), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert "no odometry topic" in proc.stdout.readline()
    time.sleep(1.0)
    proc.send_signal(sig)
    out, err = proc.communicate(timeout=30)
    assert proc.returncode == 130, (proc.returncode, out, err)
    assert "stopped: replayed" in out and "could not be republished" not in err, (out, err)
