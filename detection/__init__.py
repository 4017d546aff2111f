"""The paper's moving-object detector: pure functions from aligned scans to moving objects.

Never imports ``tracker``, rosbags, rerun or argparse.
"""
