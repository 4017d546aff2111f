"""The ``people-tracker`` command line.

Every bad input file or configuration ends with one line on stderr and exit status 2;
bad scans inside a good recording give one warning each and the run goes on.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import re
import shlex
import sys
import time

from people_tracker.tracker.errors import InputError, require

PROG = "people-tracker"


class _CliError(Exception):
    """A usage error found by argparse."""


class _Parser(argparse.ArgumentParser):
    """One-line errors; ``epilog`` may be a function, called only when the help is shown
    (the scenario list reads the shipped files: no cost to ``--help`` of other commands)."""

    def error(self, message: str):  # one line, exit 2, no usage dump
        raise _CliError(message)

    def format_help(self) -> str:
        if callable(self.epilog):
            self.epilog = self.epilog()
        return super().format_help()


def _volume(parser: argparse.ArgumentParser, default) -> None:
    """-q and -v, before the subcommand (``default`` False) or after it (not set unless given)."""
    parser.add_argument("-q", "--quiet", action="store_true", default=default, help="no warnings, no progress bar")
    parser.add_argument("-v", "--verbose", action="store_true", default=default,
                        help="every warning, none grouped")


def _scenario_list() -> str:
    """The shipped scenarios with their one-line descriptions (read without parsing YAML)."""
    from people_tracker.configs import shipped_file, shipped_names

    lines = ["shipped scenarios:"]
    for name in shipped_names("scenarios"):
        m = re.search(r"^description:\s*(.+)$", shipped_file(name, "scenarios").read_text(encoding="utf-8"), re.M)
        lines.append(f"  {name:<16} {m.group(1).strip().strip(chr(34)) if m else ''}")
    return "\n".join(lines)


class _Version(argparse.Action):
    """``--version``: the installed version, looked up only when asked (``--help`` stays fast)."""

    def __call__(self, parser, namespace, values, option_string=None):
        from people_tracker import __version__

        print(f"{PROG} {__version__}")
        parser.exit()


# what INPUT may be, for every command that reads a recording
RECORDING_HELP = "a ROS 1 .bag, a ROS 2 bag folder (or its metadata.yaml), or an .mcap or .db3 file"


def _build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog=PROG, description="Find and follow walking people in 2D laser scans.")
    p.add_argument("--version", action=_Version, nargs=0, help="show the version and exit")
    _volume(p, False)
    common = argparse.ArgumentParser(add_help=False)
    _volume(common, argparse.SUPPRESS)
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True

    run = sub.add_parser("run", help="run on a recording (or the built-in simulated scene)", parents=[common])
    run.add_argument("input", nargs="?", metavar="INPUT", help=RECORDING_HELP)
    run.add_argument("--topic", help="LaserScan topic (default: the only one)")
    run.add_argument("--config", metavar="FILE", help="YAML file overriding configs/default.yaml")
    run.add_argument("--detections", metavar="FILE.csv", help="write the moving objects of every scan")
    run.add_argument("--tracks", metavar="FILE.csv", help="write the confirmed people of every scan")
    run.add_argument("--legs", metavar="FILE.csv", help="write every leg candidate of every scan with its probability")
    run.add_argument("--follow", metavar="auto|ID", help="follow a person: the one straight ahead (auto) or a track id")
    run.add_argument("--rrd", metavar="FILE.rrd", help="save a rerun recording of every stage")
    run.add_argument("--spawn", action="store_true", help="open the rerun viewer and stream to it")

    ev = sub.add_parser("evaluate", help="score a tracks CSV against ground truth (CLEAR MOT, IDF1, OSPA)", parents=[common])
    ev.add_argument("tracks", metavar="TRACKS.csv", help="needs the columns scan_index,track_id,x,y")
    ev.add_argument("--ground-truth", required=True, metavar="BAG|GT.csv",
                    help="an annotated recording or a ground-truth CSV (scan_index,person_id,x,y)")
    ev.add_argument("--protocol", choices=("general", "following"), default="general",
                    help="general: everyone; following: the followed person over all tracks, and the "
                         "tracker's target (its target column) against them")
    ev.add_argument("--target-person", type=int, metavar="ID",
                    help="the followed person's id, when the ground truth holds everyone (following)")
    ev.add_argument("--threshold", type=float, default=0.75, metavar="M", help="match distance, metres (0.75)")
    ev.add_argument("--topic", help="scan topic of the annotated recording (every scan is a frame)")
    ev.add_argument("--gt-topic", help="ground-truth topic (leg_tracker/Person) of the recording")
    ev.add_argument("--ospa-cutoff", type=float, default=1.0, metavar="M", help="OSPA cut-off c, metres (1.0)")
    ev.add_argument("--ospa-order", type=float, default=1.0, metavar="P", help="OSPA order p (1)")
    ev.add_argument("--bearing-window", type=float, nargs=2, metavar=("MIN", "MAX"),
                    help="score only people and tracks at sensor-frame bearings MIN..MAX, degrees "
                         "(Leigh et al. used -80 12 on the moving-robot recordings)")
    ev.add_argument("--json", metavar="FILE", help="also write the figures as JSON")

    sim = sub.add_parser("simulate", help="render a simulated scenario to a ROS 2 bag (MCAP) with ground truth",
                         parents=[common], epilog=_scenario_list, formatter_class=argparse.RawDescriptionHelpFormatter)
    sim.add_argument("scenario", metavar="SCENARIO", help="a name from configs/scenarios or a YAML file")
    sim.add_argument("--output", required=True, metavar="OUT", help="bag folder to create; ground truth goes to OUT.gt.csv")
    sim.add_argument("--seed", type=int, help="override the scenario's seed")
    sim.add_argument("--people", type=int, help="number of crowd walkers (crowd scenes)")
    sim.add_argument("--duration", type=float, metavar="S", help="override the scenario's duration, seconds")
    sim.add_argument("--laser", metavar="NAME", help="one of the scenario's other lasers (its 'lasers' section)")
    sim.add_argument("--format", choices=("mcap", "sqlite3", "ros1"), default="mcap",
                     help="ROS 2 bag storage (mcap, sqlite3) or a ROS 1 .bag (default: mcap)")
    tl = sub.add_parser("train-legs", help="fit the leg model to your own laser's recordings ([train] extra)", parents=[common])
    tl.add_argument("--positive", nargs="+", required=True, metavar="BAG[:TOPIC]",
                    help="recordings with people's legs: labelled in --label-topic, or inside --box")
    tl.add_argument("--negative", nargs="+", required=True, metavar="BAG[:TOPIC]",
                    help="recordings where nobody is (every LaserScan topic, or the one after ':')")
    tl.add_argument("--output", required=True, metavar="MODEL.npz", help="the model file to write")
    tl.add_argument("--label-topic", default="/leg_cluster_positions", metavar="TOPIC",
                    help="geometry_msgs/PoseArray of leg centres in the sensor frame (default: %(default)s)")
    tl.add_argument("--box", type=float, nargs=4, metavar=("X0", "Y0", "X1", "Y1"),
                    help="no labels: every candidate inside this box (sensor frame, m) is a leg")
    tl.add_argument("--trees", type=int, default=200, help="boosting rounds (%(default)s)")
    tl.add_argument("--simulated", type=int, default=600, metavar="N",
                    help="also N scans of simulated rooms with people and furniture, every leg known (%(default)s; 0: none)")
    tl.add_argument("--depth", type=int, default=4, help="depth of each tree (%(default)s)")
    tl.add_argument("--simulated-resolutions", type=float, nargs="+", default=[0.25, 0.35, 0.5, 0.75], metavar="DEG",
                    help="beam spacings of the simulated lasers, degrees (default: %(default)s)")
    ros = sub.add_parser("ros2", help="run as a live ROS 2 node ([ros2] extra): scans in, people out", parents=[common],
                         epilog="Publishes people (geometry_msgs/PoseArray), people_markers (visualization_msgs/"
                                "MarkerArray), people_target (geometry_msgs/PoseStamped) and, with --legs, legs "
                                "(PoseArray), all in the fixed frame. Every option is also a ROS parameter: "
                                "--ros-args -p scan_topic:=/front_scan. Ctrl-C: exit 0 with latency figures.")
    ros.add_argument("--scan-topic", default="/scan", help="sensor_msgs/LaserScan topic (%(default)s)")
    odom = ros.add_mutually_exclusive_group()
    odom.add_argument("--odom-topic", default="/odom", help="nav_msgs/Odometry topic (%(default)s)")
    odom.add_argument("--no-odom", action="store_true", help="no odometry: scan matching alone finds the motion")
    ros.add_argument("--mount", type=float, nargs=3, default=[0.0, 0.0, 0.0], metavar=("X", "Y", "YAW_DEG"),
                     help="the laser in the odometry's base frame: metres, metres, degrees (0 0 0)")
    ros.add_argument("--fixed-frame", default="odom", help="frame of the published positions (%(default)s)")
    ros.add_argument("--config", metavar="FILE", help="YAML file overriding configs/default.yaml")
    ros.add_argument("--follow", metavar="auto|ID", help="follow a person: the one straight ahead (auto) or a track id")
    ros.add_argument("--legs", action="store_true", help="also publish the likely leg candidates on legs")
    ros.add_argument("--queue", type=int, default=10, metavar="N",
                     help="scans waiting to be tracked before the oldest is dropped (%(default)s); more trades "
                          "latency for every scan, e.g. for a recording replayed faster than it was made")
    rp = sub.add_parser("replay", help="publish a recording's scans and odometry on ROS 2 ([ros2] extra)",
                        parents=[common])
    rp.add_argument("input", metavar="INPUT", help=RECORDING_HELP)
    rp.add_argument("--topic", help="LaserScan topic (default: the only one)")
    rp.add_argument("--rate", type=float, default=1.0, help="times the recorded pace (%(default)s)")
    rp.add_argument("--wait", type=float, default=5.0, metavar="S",
                    help="wait up to S seconds for a subscriber before starting (%(default)s)")
    bench = sub.add_parser("bench", help="accuracy and speed on every recording and simulated scene", parents=[common])
    bench.add_argument("--data", metavar="DIR", help="folder of recordings (default: $PEOPLE_TRACKER_DATA, "
                       "else ../shared/data)")
    bench.add_argument("--config", metavar="FILE", help="YAML file overriding configs/default.yaml")
    bench.add_argument("--quick", action="store_true", help="the first 200 scans and 6 s scenes")
    bench.add_argument("--only", nargs="+", metavar="TEXT",
                       help="only the inputs whose name contains one of these (e.g. negative_2 crowd)")
    return p


def _progress(total: int, quiet: bool):
    from tqdm import tqdm
    # disable=None: only on a terminal; delay: only for runs over a few seconds
    return tqdm(total=total, unit="scan", file=sys.stderr, disable=True if quiet else None,
                delay=2.0, leave=False, dynamic_ncols=True)


def note_first_compile(log, terminal: bool | None = None) -> None:
    """Say on stderr (through ``log``) that the compiled kernels are being compiled, when
    none of them has a compiled copy on disk yet: the first run on a machine is otherwise
    silent for about half a minute before its first scan. Only on a terminal (``terminal``:
    whether stderr is one), as the progress bar: a script reading stderr gets no notes."""
    from people_tracker.models import compiled

    terminal = sys.stderr.isatty() if terminal is None else terminal
    if terminal and compiled.ENABLED and compiled.uncompiled():
        log.warning("compiling the fast kernels for this machine (once: about half a minute, then cached; "
                    "PEOPLE_TRACKER_COMPILED=0 runs without them)")


def _print_v_min(params, resolution: float) -> None:
    from people_tracker.detection.detector import v_min

    for dt, speeds in v_min(params, resolution).items():
        print(f"V_min = Δd_c/Δt for Δt {dt:g} s: " + ", ".join(
            f"{v:.2f} m/s at {r:g} m" for v, r in zip(speeds, (1, 3, 5))))


def _run_outputs(args) -> list[str]:
    """Every file ``run`` writes: the CSVs, their resolved configurations and the rerun file."""
    csvs = [out for out in (args.detections, args.tracks, args.legs) if out]
    return csvs + [f"{out}.config.yaml" for out in csvs] + ([args.rrd] if args.rrd else [])


def _run_header(args, rec) -> str:
    """What made an output, as YAML comments (the file still loads as a --config)."""
    from people_tracker import __version__

    return (f"# written by {PROG} {__version__}\n"
            f"# command: {shlex.join([PROG, *getattr(args, 'argv', [])])}\n"
            f"# input: {rec.path}\n# topic: {rec.topic}\n")


def _cmd_run(args) -> int:
    from people_tracker.tracker.config import load_config
    from people_tracker.tracker.io.atomic import check_outputs
    from people_tracker.tracker.io.recording import Recording

    config = load_config(args.config)
    follow = None
    if args.follow is not None:
        if args.follow != "auto" and not args.follow.isdigit():
            raise InputError(f"--follow takes auto or a track id, got '{args.follow}'")
        follow = args.follow if args.follow == "auto" else int(args.follow)
    if args.input is None and args.topic:
        raise InputError("--topic needs an INPUT recording")
    check_outputs([args.input, args.config], _run_outputs(args))
    t0 = time.perf_counter()
    truth = _ground_truth_by_scan(args.input, args.topic) if (args.rrd or args.spawn) and args.input else None
    with _ctrl_c_latch() as interrupted:
        sink = _make_sink(args)
        try:
            if args.input is None:
                from people_tracker.tracker.io.simulated import DEFAULT_SCENE, SimulatedSource
                source = SimulatedSource(DEFAULT_SCENE)
            else:
                source = Recording(args.input, args.topic, config.odometry)
            _run_loop(args, config, follow, source, contextlib.ExitStack(), sink, truth, t0, interrupted)
            if interrupted():
                raise KeyboardInterrupt
        except BaseException:
            sink.abort()
            raise
        sink.close()
    return 0


def _ground_truth_by_scan(path, topic) -> dict | None:
    """Sensor-frame ground truth per scan index of an annotated recording (None without)."""
    from people_tracker.tracker.io.ground_truth import read_bag_ground_truth

    gt = read_bag_ground_truth(path, topic, required=False)
    if gt is None:
        return None
    out: dict = {}
    for k, x, y in zip(gt.scan_index.tolist(), gt.x, gt.y):
        out.setdefault(k, []).append((x, y))
    return out


def _make_sink(args):
    from people_tracker.tracker.sinks import NullSink

    if not (args.rrd or args.spawn):
        return NullSink()
    # rerun's own log lines (coloured, several per failure) would repeat what our one line
    # says; read when rerun is first imported
    os.environ.setdefault("RUST_LOG", "off")
    require("rerun", "viz", "--rrd and --spawn (rerun visualisation)")
    from people_tracker.tracker.viz_rerun import RerunSink
    return RerunSink(args.rrd, args.spawn)


def _run_loop(args, config, follow, source, stack, sink, truth, t0, interrupted=lambda: False) -> None:
    """Track every scan of ``source``, writing the outputs; ``interrupted`` says whether
    Ctrl-C came (see :func:`_ctrl_c_latch`): the run then ends before the next scan, and
    before anything is published."""
    import gc
    import logging

    import numpy as np

    from people_tracker.tracker.config import dump_config
    from people_tracker.tracker.io import outputs
    from people_tracker.tracker.io.atomic import atomic_output
    from people_tracker.tracker.people_tracker import PeopleTracker, tracks_in_sensor_frame
    from people_tracker.tracker.scan_checks import ScanChecker

    log = logging.getLogger(PROG)
    with source as rec, stack:
        det_file = stack.enter_context(atomic_output(args.detections)) if args.detections else None
        trk_file = stack.enter_context(atomic_output(args.tracks)) if args.tracks else None
        leg_file = stack.enter_context(atomic_output(args.legs)) if args.legs else None
        # the resolved configuration beside each CSV, published with it when the run ends
        sidecars = [stack.enter_context(atomic_output(f"{out}.config.yaml"))
                    for out in (args.detections, args.tracks, args.legs) if out]
        if det_file:
            outputs.write_header(det_file)
        if trk_file:
            outputs.write_tracks_header(trk_file)
        if leg_file:
            outputs.write_legs_header(leg_file)
        tracker = PeopleTracker.from_config(config, follow)
        note_first_compile(log)
        _print_v_min(tracker.detector.params, rec.resolution)
        # what start-up made (the modules, the leg model) lives to the end: out of the cyclic
        # collector's sight, its full collections no longer walk it (~7 ms each, a few a
        # hundred scans; 0.2-0.3 s of a run, measured)
        gc.freeze()
        checker = ScanChecker(config.scan_checks.stamp_jump_periods, config.scan_checks.beam_count_confirm)
        used = skipped = restarts = with_pose = n_objects = n_track_rows = 0
        people_ids: set[int] = set()
        first_stamp = last_stamp = None
        path_m = 0.0
        last_pose = None
        with _progress(rec.scan_count, args.quiet) as bar:
            for record in rec.scans():
                if interrupted():
                    raise KeyboardInterrupt
                bar.update(1)
                verdict = checker.check(record.scan, record.problem)
                if verdict.reason:
                    log.warning("scan %d %s", record.index, verdict.reason)
                if not verdict.use:
                    skipped += 1
                    continue
                used += 1
                restarts += verdict.restart
                scan = record.scan
                if verdict.restart:
                    tracker.reset()
                t_step = time.perf_counter()
                tracks = tracker.step(scan, record.pose, record.pose_last_beam)
                latency = time.perf_counter() - t_step
                if truth is not None:
                    sink_truth = np.array(truth.get(record.index, []), dtype=float).reshape(-1, 2)
                elif getattr(rec, "truths", None):
                    tr = rec.truths[-1]
                    sink_truth = tr.torso_sensor[tr.visible]
                else:
                    sink_truth = None
                sink.scan(record.index, scan.stamp, tracker.last, latency, sink_truth)
                found = tracker.last.detection
                n_objects += len(found.objects)
                n_track_rows += len(tracks)
                people_ids.update(t.track_id for t in tracks)
                if det_file:
                    outputs.write_rows(det_file, record.index, scan.stamp, found.objects)
                if trk_file:
                    outputs.write_track_rows(trk_file, record.index, scan.stamp, tracks,
                                             tracks_in_sensor_frame(tracks, tracker.last.pose))
                if leg_file:
                    last = tracker.last
                    outputs.write_leg_rows(leg_file, record.index, scan.stamp, last.scan.valid_points, last.legs,
                                           last.leg_scores)
                first_stamp = scan.stamp if first_stamp is None else first_stamp
                last_stamp = scan.stamp
                if record.pose is not None:
                    with_pose += 1
                    if last_pose is not None:
                        path_m += math.hypot(record.pose.x - last_pose.x, record.pose.y - last_pose.y)
                    last_pose = record.pose
            if interrupted():  # Ctrl-C during the last scan: nothing is published
                raise KeyboardInterrupt
        elapsed = time.perf_counter() - t0
        span = (last_stamp - first_stamp) if used > 1 else 0.0
        rate = f", {(used - 1) / span:.1f} Hz" if span > 0 else ""
        print(f"input: {rec.path} topic {rec.topic} (frame {rec.laser_frame}, {rec.n_beams} beams{rate})")
        if rec.fixed_frame is None:
            print("odometry: none (scans are compared without a pose prior)")
        else:
            print(f"odometry: {rec.odometry}; fixed frame {rec.fixed_frame}; "
                  f"{with_pose} of {used} scans posed; sensor travelled {path_m:.1f} m")
        total = used + skipped
        print(f"scans: {total} read, {used} used, {skipped} skipped, {restarts} history restarts; "
              f"{span:.1f} s of recording in {elapsed:.2f} s ({total / max(elapsed, 1e-9):.0f} scans/s)")
        print(f"moving objects: {n_objects} ({n_objects / max(used, 1):.2f} per scan)"
              + (f" written to {args.detections}" if args.detections else ""))
        print(f"people: {len(people_ids)} confirmed tracks, {n_track_rows / max(used, 1):.2f} per scan"
              + (f" written to {args.tracks}" if args.tracks else ""))
        if tracker.selector is not None:
            events = tracker.selector.events
            print(f"following: {', '.join(events) if events else 'no target found'}")
        for fh in sidecars:
            fh.write(_run_header(args, rec) + dump_config(config))
        if args.rrd:
            print(f"rerun recording: {args.rrd} (open it with: rerun {args.rrd})")


def _cmd_evaluate(args) -> int:
    import json
    import logging

    from people_tracker.tracker.evaluation import evaluate, format_table, frame_mismatches
    from people_tracker.tracker.io.atomic import atomic_output, check_outputs
    from people_tracker.tracker.io.ground_truth import read_ground_truth
    from people_tracker.tracker.io.tracks_csv import read_tracks_csv

    require("motmetrics", "eval", "people-tracker evaluate")
    for name, value in (("--threshold", args.threshold), ("--ospa-cutoff", args.ospa_cutoff),
                        ("--ospa-order", args.ospa_order)):
        if not (math.isfinite(value) and value > 0):
            raise InputError(f"{name} must be a positive number, got {value}")
    window = args.bearing_window
    if window is not None and not (all(math.isfinite(b) and -180 <= b <= 180 for b in window) and window[0] < window[1]):
        raise InputError(f"--bearing-window needs MIN < MAX, both in -180..180 degrees, got {window[0]:g} {window[1]:g}")
    check_outputs([args.tracks, args.ground_truth], [args.json])
    tracks = read_tracks_csv(args.tracks)
    gt = read_ground_truth(args.ground_truth, args.topic, args.gt_topic)
    for reason in frame_mismatches(gt, tracks):
        logging.getLogger(PROG).warning(reason)
    if args.target_person is not None and args.protocol != "following":
        raise InputError("--target-person needs --protocol following")
    result = evaluate(gt, tracks, args.protocol, args.threshold, args.ospa_cutoff, args.ospa_order,
                      bearing_window_deg=None if window is None else tuple(window), target_person=args.target_person)
    result["tracks_file"] = str(args.tracks)
    result["ground_truth_file"] = str(args.ground_truth)
    print(format_table(result))
    if args.json:
        with atomic_output(args.json) as fh:
            json.dump({k: (None if isinstance(v, float) and v != v else v) for k, v in result.items()}, fh, indent=2)
            fh.write("\n")
    return 0


def _cmd_simulate(args) -> int:
    from people_tracker.tracker.io.simulated import simulate_to_bag

    if args.people is not None and args.people < 0:
        raise InputError("--people must be 0 or more")
    if args.duration is not None and not args.duration > 0:
        raise InputError("--duration must be positive")
    t0 = time.perf_counter()
    with _progress(None, args.quiet) as bar:
        bag, gt, n, rows, odometry = simulate_to_bag(args.scenario, args.output, args.seed, args.people, args.duration,
                                           args.format, progress=bar.update, laser=args.laser)
    topics = "/scan, /odom, /tf, /tf_static" if odometry else "/scan, /tf_static"
    print(f"wrote {bag} ({n} scans on {topics}; {args.format}) and {gt} "
          f"({rows} visible people) in {time.perf_counter() - t0:.1f} s")
    return 0


def _cmd_bench(args) -> int:
    require("motmetrics", "eval", "people-tracker bench")
    from pathlib import Path

    from people_tracker.tracker.bench import run_bench
    from people_tracker.tracker.config import load_config

    config = load_config(args.config)
    data = Path(args.data or os.environ.get("PEOPLE_TRACKER_DATA") or "../shared/data")
    if args.data and not data.is_dir():
        raise InputError(f"data folder '{data}' does not exist")
    import logging

    import people_tracker.tracker.people_tracker  # noqa: F401  (its kernels, for the note below)
    note_first_compile(logging.getLogger(PROG))
    run_bench(config, data, args.quick, sys.stdout, args.only)
    return 0


def _bag_and_topic(arg: str) -> tuple[str, str | None]:
    """``BAG`` or ``BAG:TOPIC``."""
    if not os.path.exists(arg) and ":" in arg:
        bag, topic = arg.rsplit(":", 1)
        return bag, topic
    return arg, None


def _cmd_train_legs(args) -> int:
    from people_tracker.tracker import train_legs as T
    from people_tracker.tracker.io.atomic import atomic_output, check_outputs

    require("sklearn", "train", "people-tracker train-legs")
    if args.box is not None and not (args.box[0] < args.box[2] and args.box[1] < args.box[3]):
        raise InputError("--box needs X0 < X1 and Y0 < Y1 (sensor frame, metres)")
    if not 10 <= args.trees <= 5000:
        raise InputError("--trees must be between 10 and 5000")
    if not 0 <= args.simulated <= 100000:
        raise InputError("--simulated must be between 0 and 100000")
    if not 1 <= args.depth <= 12:
        raise InputError("--depth must be between 1 and 12")
    if not all(0.01 <= r <= 10.0 for r in args.simulated_resolutions):
        raise InputError("--simulated-resolutions takes beam spacings between 0.01 and 10 degrees")
    positive_args = [_bag_and_topic(a) for a in args.positive]
    negative_args = [_bag_and_topic(a) for a in args.negative]
    check_outputs([b for b, _ in positive_args + negative_args], [args.output])
    t0 = time.perf_counter()
    positives, negatives, names = [], [], []
    for bag, topic in positive_args:
        positives.append(T.read_labelled(bag, topic, args.label_topic, tuple(args.box) if args.box else None))
        names.append(f"{bag}{':' + topic if topic else ''}")
    for bag, topic in negative_args:
        for t in ([topic] if topic else T.laser_topics(bag)):
            negatives.append([s for _, s in T.read_scans(bag, t)])
            names.append(f"{bag}:{t}")
    x, y, groups, recorded, moved = T.training_set(positives, negatives, args.simulated, args.simulated_resolutions)
    print(f"candidates: {int(y.sum())} legs, {int(len(y) - y.sum())} others (each scan also at every 2nd and 3rd "
          f"beam), from {sum(map(len, positives))} labelled scans, their legs pasted into "
          f"{moved} empty ones, {sum(map(len, negatives))} empty scans and {args.simulated} "
          f"simulated ones")
    model = T.fit(x, y, groups, n_trees=args.trees, depth=args.depth, meta={"trained_on": names},
                  calibrate_on=recorded)
    with atomic_output(args.output, "wb") as fh:
        model.save(fh)
    print(f"wrote {args.output} ({len(model.feature)} trees of depth {model.depth}, "
          f"{model.meta['calibration']}) in {time.perf_counter() - t0:.1f} s")
    return 0


def _cmd_ros2(args) -> int:
    import math as _math

    from people_tracker.tracker.config import load_config
    from people_tracker.tracker.ros2_node import NodeOptions, run_node

    config = load_config(args.config)
    if args.follow is not None and args.follow != "auto" and not args.follow.isdigit():
        raise InputError(f"--follow takes auto or a track id, got '{args.follow}'")
    x, y, yaw_deg = args.mount
    if not all(_math.isfinite(v) for v in args.mount):
        raise InputError("--mount takes three finite numbers: X Y YAW_DEG")
    if args.queue < 1:
        raise InputError(f"--queue takes a number of scans, 1 or more, got {args.queue}")
    options = NodeOptions(args.scan_topic, "" if args.no_odom else args.odom_topic, (x, y, _math.radians(yaw_deg)),
                          args.fixed_frame, args.follow or "", args.legs, args.queue)
    return run_node(options, config, args.ros_args)


def _cmd_replay(args) -> int:
    from people_tracker.tracker.config import load_config
    from people_tracker.tracker.ros2_node import replay

    return replay(args.input, args.topic, args.rate, load_config(), args.wait, args.ros_args)


@contextlib.contextmanager
def _ctrl_c_latch():
    """Ctrl-C during a run, remembered as well as raised: yields a function that says
    whether it came. A KeyboardInterrupt raised while a library's compiled code runs may
    never reach the loop (a CI run once ended ``run --rrd`` with exit status 0 after
    Ctrl-C, its outputs published); the loop asks at every scan and ends the run then. Left
    alone where Ctrl-C is not Python's to handle: ignored (a run started in the background
    by a shell inherits that), handled by someone else, or off the main thread."""
    import signal
    import threading

    came = False

    def handler(signum, frame):
        nonlocal came
        came = True
        raise KeyboardInterrupt

    ours = (threading.current_thread() is threading.main_thread()
            and signal.getsignal(signal.SIGINT) is signal.default_int_handler)
    if ours:
        signal.signal(signal.SIGINT, handler)
    try:
        yield lambda: came
    finally:
        if ours:
            signal.signal(signal.SIGINT, signal.default_int_handler)


def _interrupted(exc: BaseException) -> bool:
    """Whether ``exc`` stands for Ctrl-C: a KeyboardInterrupt that reached Python inside a
    compiled call comes back wrapped (numba's dispatcher: "SystemError: ... returned a
    result with an exception set", the interrupt as its cause)."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``people-tracker`` console script; returns the exit status."""
    argv = sys.argv[1:] if argv is None else argv
    ros_args = None
    if "--ros-args" in argv:  # ROS's own arguments go to rclpy, untouched
        k = argv.index("--ros-args")
        argv, ros_args = argv[:k], argv[k:]
    try:
        args = _build_parser().parse_args(argv)
    except _CliError as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
    from people_tracker.tracker.cli_log import setup_logging

    handler = setup_logging(args.quiet, args.verbose and not args.quiet)
    args.argv = list(argv)
    args.ros_args = ["--ros-args", *ros_args[1:]] if ros_args else None
    commands = {"run": _cmd_run, "evaluate": _cmd_evaluate, "simulate": _cmd_simulate, "bench": _cmd_bench,
                "train-legs": _cmd_train_legs, "ros2": _cmd_ros2, "replay": _cmd_replay}
    try:
        return commands[args.command](args)
    except InputError as exc:
        handler.summary()
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        handler.summary()
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return 0
    except Exception as exc:  # never a traceback for users; PEOPLE_TRACKER_DEBUG=1 shows it
        if _interrupted(exc):
            handler.summary()
            print(f"{PROG}: interrupted", file=sys.stderr)
            return 130
        if os.environ.get("PEOPLE_TRACKER_DEBUG"):
            raise
        handler.summary()
        print(f"{PROG}: internal error: {type(exc).__name__}: {' '.join(str(exc).split())[:300]} "
              f"(set PEOPLE_TRACKER_DEBUG=1 for the traceback)", file=sys.stderr)
        return 1
    finally:
        handler.summary()


if __name__ == "__main__":
    sys.exit(main())
