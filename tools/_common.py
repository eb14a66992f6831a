"""Shared helpers of the command-line scripts in tools/."""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from diefillpost import series  # noqa: E402


def frame_at(case, time=None):
    """The output nearest to `time` (the last one when None: then only that file is
    read, so a damaged older one does not matter).  A frame without particles is a
    ValueError naming its file."""
    if time is None:
        frame = series.read_frame(series.last_path(case))
    else:
        frame = series.read_frame(min(series.list_frames(case), key=lambda e: abs(e[0] - time))[1])
    if frame.count == 0:
        raise ValueError(f"'{frame.path}' (t = {frame.time:g} s) holds no particles: nothing to measure or draw")
    return frame


def argument_parser(doc):
    """An argparse parser whose help is -help, as in OpenFOAM's and demLib's tools
    (and -h, --help); argparse alone takes '-help' for '-h elp' and fails."""
    parser = argparse.ArgumentParser(description=doc, add_help=False,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("-help", "-h", "--help", action="help", help="show this help and exit")
    return parser


def out_dir(case):
    d = os.path.join(case, "postProcessing")
    os.makedirs(d, exist_ok=True)
    return d


def run_main(main, *args):
    """Runs a tool's main(): a missing file, a missing keyword or a bad value
    ends with one line naming it and exit status 1, not a Python traceback
    (set DIEFILL_TRACEBACK=1 to see the traceback)."""
    name = os.path.basename(sys.argv[0])
    try:
        status = main(*args)
    except (FileNotFoundError, KeyError, ValueError, OSError) as e:
        if os.environ.get("DIEFILL_TRACEBACK"):
            raise
        if isinstance(e, OSError) and e.filename:
            message = f"{e.strerror}: '{e.filename}'"
        elif isinstance(e, KeyError) and e.args:
            message = e.args[0]  # str() of a KeyError adds quotes
        else:
            message = e
        print(f"{name}: error: {message}", file=sys.stderr)
        sys.exit(1)
    sys.exit(status or 0)
