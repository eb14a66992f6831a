"""The wall-time table diefillFoam prints at the end of its time loop (and when it is
stopped; applications/diefillFoam/phaseTimes.C):

    Wall time of the time loop, 212 s (2 ranks: the most over ranks, and least - most):
        DEM (particle steps)             170 s  80.2 %  (168 - 170 s)
          of which in the DEM's exchanges  9.1 s  4.3 %  (7.7 - 9.1 s)
        coupling (void fraction, drag)    20 s   9.4 %  (...)

One reader for the bench (bench/run) and the tests (tests/diefillFoam/checks.py)."""
import re
from collections import namedtuple

# The rows' names as printed, by the short keys the bench reports them under
PHASES = {"dem": "DEM (particle steps)", "coupling": "coupling (void fraction, drag)",
          "air": "air (PIMPLE loop)", "output": "output (fields, restart files)",
          "rest": "rest (time control, progress)"}
EXCHANGES = "of which in the DEM's exchanges"

# least and most are None in a serial run's table (one process: no range)
Row = namedtuple("Row", "seconds percent least most")
Table = namedtuple("Table", "total ranks rows")

_TABLE = re.compile(r"Wall time of the time loop, ([0-9.eE+-]+) s(?: \((\d+) ranks[^)]*\))?:\n((?:    .*(?:\n|$))+)")
_ROW = re.compile(r"\s{4}\s*(\S.*?)\s+([0-9.eE+-]+) s\s+([0-9.eE+-]+) %"
                  r"(?:\s+\(([0-9.eE+-]+) - ([0-9.eE+-]+) s\))?")


def parse(text):
    """The last wall-time table in a log's text (a continued log may hold several), or
    None if there is none.  rows: name as printed -> Row; ranks: 1 when the header
    names none (a serial run)."""
    tables = list(_TABLE.finditer(text))
    if not tables:
        return None
    m = tables[-1]
    rows = {}
    for line in m.group(3).splitlines():
        r = _ROW.match(line)
        if r:
            least, most = (float(r.group(4)), float(r.group(5))) if r.group(4) is not None else (None, None)
            rows[r.group(1).strip()] = Row(float(r.group(2)), float(r.group(3)), least, most)
    return Table(float(m.group(1)), int(m.group(2) or 1), rows)


def phase_seconds(table):
    """The phases' seconds by short key (dem, coupling, air, output, rest), those the table has."""
    return {key: table.rows[name].seconds for key, name in PHASES.items() if name in table.rows}
