"""Shared helpers of the command-line scripts in tools/."""
import argparse
import math
import os
import sys

import numpy as np

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


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        """One line naming the option and what was wrong (argparse would print the
        whole usage first); exit status 2 as argparse."""
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} -help)\n")


def argument_parser(doc):
    """An argparse parser whose help is -help, as in OpenFOAM's and demLib's tools
    (and -h, --help); argparse alone takes '-help' for '-h elp' and fails.  A bad
    option is one line: '<tool>: error: argument -X: ...'."""
    parser = _Parser(description=doc, add_help=False, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("-help", "-h", "--help", action="help", help="show this help and exit")
    return parser


def _number(text, kind=float):
    try:
        value = kind(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a {'whole ' if kind is int else ''}number, got '{text}'") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite number, got '{text}'")
    return value


def finite(text):
    """argparse type: a finite number (not nan or inf)."""
    return _number(text)


def positive(text):
    """argparse type: a finite number above zero."""
    value = _number(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"expected a number above zero, got '{text}'")
    return value


def non_negative(text):
    """argparse type: a finite number, zero or above."""
    value = _number(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a number of zero or more, got '{text}'")
    return value


def positive_int(text):
    """argparse type: a whole number of at least 1."""
    value = _number(text, int)
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a whole number of at least 1, got '{text}'")
    return value


def direction(parser, option, vector, across=None, across_option=None):
    """`vector` (given with `option`) as a unit vector; a zero vector, or one along
    `across` (given with `across_option`) when that is given, is a parser error."""
    v = np.asarray(vector, float)
    n = float(np.linalg.norm(v))
    if not n > 0:
        parser.error(f"argument {option}: the direction ({' '.join(f'{x:g}' for x in v)}) is zero")
    v = v / n
    if across is not None and np.linalg.norm(np.cross(v, np.asarray(across, float) / np.linalg.norm(across))) < 1e-6:
        parser.error(f"argument {option}: the direction ({' '.join(f'{x:g}' for x in vector)}) is along "
                     f"{across_option}; expected one across it")
    return v


def ordered(parser, option, low, high, what="values"):
    """A parser error unless low < high (the two `what` of `option`)."""
    if not low < high:
        parser.error(f"argument {option}: expected the first of the two {what} below the second, got {low:g} {high:g}")


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
