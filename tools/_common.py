"""Shared helpers of the command-line scripts in tools/."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from diefillpost import series  # noqa: E402


def frame_at(case, time=None):
    """The output nearest to `time` (the last one when None)."""
    entries = series.list_frames(case)
    if time is None:
        return series.read_frame(entries[-1][1])
    return series.read_frame(min(entries, key=lambda e: abs(e[0] - time))[1])


def out_dir(case):
    d = os.path.join(case, "postProcessing")
    os.makedirs(d, exist_ok=True)
    return d
