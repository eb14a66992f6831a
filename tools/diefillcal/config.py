"""The calibration dictionary (docs/calibration.md): read, checked against the cases it names,
turned into Stage objects.  Every error names the file, the keyword and what was expected."""
import os
import re

from diefillpost import foamdict

from . import casefile

SETTINGS = ("quick", "full")
FAILURE_CHOICES = ("continue", "stop")


class InputError(Exception):
    """Bad input: the message names the file, the keyword and what was expected."""


class Parameter:
    def __init__(self, keyword, low, high):
        self.keyword, self.low, self.high = keyword, low, high

    @property
    def name(self):
        """The last two names of the keyword path, e.g. 'sand-steel/friction'."""
        return "/".join(self.keyword.split("/")[-2:])

    def from_unit(self, u):
        return self.low + (self.high - self.low) * u

    def to_unit(self, v):
        return (v - self.low) / (self.high - self.low)


class Target:
    def __init__(self, key, value, sigma):
        self.key, self.value, self.sigma = key, value, sigma


class Stage:
    def __init__(self, name):
        self.name = name
        self.case = None
        self.setting = "quick"
        self.allrun_options = []
        self.fixed = {}
        self.parameters = []
        self.targets = []
        self.initial_runs = None
        self.min_runs = None
        self.max_runs = None
        self.tolerance = 1.0
        self.ei_tolerance = 0.01
        self.choose = "nearest"
        self.nearest_runs = 0
        self.start_run = True

    @property
    def first_runs(self):
        """Runs before the surrogate proposes: the case's own values (startRun) and the design."""
        return self.initial_runs + (1 if self.start_run and self.parameters else 0)

    def record(self, carried):
        """What the runs of this stage mean: a restart with any of it changed is refused."""
        return {"case": self.case, "setting": self.setting, "allrunOptions": self.allrun_options,
                "fixed": {**carried, **self.fixed},
                "parameters": [[p.keyword, p.low, p.high] for p in self.parameters],
                "initialRuns": self.initial_runs, "startRun": self.start_run}


class Calibration:
    def __init__(self):
        self.path = None
        self.work_dir = None
        self.runs_in_parallel = 1
        self.threads_per_run = 1
        self.on_failure = "continue"
        self.seed = 1
        self.stages = []


def _number(d, key, where, default=None, low=None, high=None, integer=False):
    if key not in d:
        if default is None:
            raise InputError(f"{where}: keyword '{key}' is missing; expected a number")
        return default
    v = d[key]
    if not isinstance(v, float) or (integer and v != int(v)):
        raise InputError(f"{where}: keyword '{key}' is {v!r}; expected a {'whole ' if integer else ''}number")
    if (low is not None and v < low) or (high is not None and v > high):
        bounds = f"at least {low:g}" if high is None else f"{low:g} to {high:g}"
        raise InputError(f"{where}: keyword '{key}' is {v:g}; expected {bounds}")
    return int(v) if integer else v


def _word(d, key, where, choices, default):
    v = d.get(key, default)
    if v not in choices:
        raise InputError(f"{where}: keyword '{key}' is {v!r}; expected one of {', '.join(choices)}")
    return v


def _unknown_keys(d, known, where):
    extra = [k for k in d if k not in known]
    if extra:
        raise InputError(f"{where}: unknown keyword '{extra[0]}'; expected {', '.join(known)}")


def known_result_keys(case):
    """The results.json keys the case's post-processing tool writes, read from the tool that
    its Allrun names (tools/NAME.py); None when they cannot be told before a run."""
    allrun = os.path.join(case, "Allrun")
    try:
        text = open(allrun).read()
    except OSError:
        return None
    tools = re.findall(r"tools/(\w+)\.py", text)
    keys = set()
    for tool in tools:
        path = os.path.join(os.environ.get("DIEFILL_DIR", ""), "tools", tool + ".py")
        if os.path.exists(path):
            keys |= set(re.findall(r'"(\w+)":\s*\{"value"', open(path).read()))
    return keys or None


def read(path, work_dir=None):
    """The Calibration the dictionary at `path` describes, checked."""
    if not os.path.isfile(path):
        raise InputError(f"{path}: no such file; expected a calibration dictionary (see diefillCalibrate -help)")
    try:
        d = foamdict.read(path)
    except (KeyError, IndexError, ValueError) as e:
        raise InputError(f"{path}: cannot be read as a dictionary ({e})") from None
    base = os.path.dirname(os.path.abspath(path))
    c = Calibration()
    c.path = os.path.abspath(path)
    _unknown_keys(d, ["workDir", "runsInParallel", "threadsPerRun", "onFailure", "seed", "stages"], path)
    wd = work_dir or os.path.expandvars(str(d.get("workDir", "calibration")))
    c.work_dir = os.path.abspath(os.path.join(base, wd)) if not work_dir else os.path.abspath(wd)
    c.runs_in_parallel = _number(d, "runsInParallel", path, 1, 1, None, True)
    c.threads_per_run = _number(d, "threadsPerRun", path, 1, 1, None, True)
    c.on_failure = _word(d, "onFailure", path, FAILURE_CHOICES, "continue")
    c.seed = _number(d, "seed", path, 1, 0, None, True)
    stages = d.get("stages")
    if not isinstance(stages, dict) or not stages:
        raise InputError(f"{path}: keyword 'stages' is missing or empty; expected stages {{ NAME {{ case ...; parameters {{...}} targets {{...}} }} }}")
    for name, sd in stages.items():
        where = f"{path}: stages/{name}"
        if not isinstance(sd, dict):
            raise InputError(f"{where}: expected a dictionary")
        s = _read_stage(name, sd, where, base)
        c.stages.append(s)
    # A later stage receives the earlier stages' results: their keywords must exist in its case.
    for i, s in enumerate(c.stages):
        source = casefile.source_file(s.case)
        for earlier in c.stages[:i]:
            for p in earlier.parameters:
                try:
                    casefile.check_tunable(source, p.keyword)
                except KeyError as e:
                    raise InputError(f"{path}: stages/{s.name} receives '{p.keyword}' from stage '{earlier.name}', "
                                     f"but {e.args[0]}") from None
    return c


def _read_stage(name, sd, where, base):
    s = Stage(name)
    _unknown_keys(sd, ["case", "setting", "allrunOptions", "fixed", "parameters", "targets", "initialRuns",
                       "minRuns", "maxRuns", "tolerance", "eiTolerance", "choose", "startRun", "nearestRuns"], where)
    if "case" not in sd:
        raise InputError(f"{where}: keyword 'case' is missing; expected the folder of a case with an Allrun (a tutorial)")
    case = os.path.expandvars(str(sd["case"]))
    case = os.path.abspath(os.path.join(base, case))
    if not os.path.isfile(os.path.join(case, "Allrun")) or not os.path.isfile(casefile.source_file(case)):
        raise InputError(f"{where}: keyword 'case' is '{case}', which has no Allrun and constant/demProperties; "
                         f"expected a case folder such as $DIEFILL_DIR/tutorials/calibration/inclinedPlate")
    s.case = case
    s.setting = _word(sd, "setting", where, SETTINGS, "quick")
    opts = sd.get("allrunOptions", [])
    opts = opts if isinstance(opts, list) else [opts]
    s.allrun_options = [o if isinstance(o, str) else f"{o:g}" for o in opts]
    if any(o in ("-quick", "-threads") for o in s.allrun_options):
        raise InputError(f"{where}: keyword 'allrunOptions' holds -quick or -threads; set them with 'setting' and 'threadsPerRun'")
    source = casefile.source_file(case)

    def keyword_in_case(keyword, kind):
        try:
            casefile.check_tunable(source, keyword)
        except KeyError as e:
            raise InputError(f"{where}/{kind}: {e.args[0]}") from None

    fixed = sd.get("fixed", {})
    if not isinstance(fixed, dict):
        raise InputError(f"{where}: keyword 'fixed' expected a dictionary of 'keyword/path value;'")
    for keyword, value in fixed.items():
        keyword_in_case(keyword, "fixed")
        if not isinstance(value, float):
            raise InputError(f"{where}/fixed: '{keyword}' is {value!r}; expected a number")
        _check_limits(keyword, [value], f"{where}/fixed")
        s.fixed[keyword] = value
    # No parameters: a check stage, one run of the case at the earlier stages' results.
    params = sd.get("parameters", {})
    if not isinstance(params, dict):
        raise InputError(f"{where}: keyword 'parameters' expected a dictionary, e.g. "
                         f"parameters {{ interactions/sand-steel/friction (0.3 0.9); }}")
    for keyword, rng in params.items():
        keyword_in_case(keyword, "parameters")
        if not (isinstance(rng, list) and len(rng) == 2 and all(isinstance(v, float) for v in rng) and rng[0] < rng[1]):
            raise InputError(f"{where}/parameters: '{keyword}' is {rng!r}; expected a range (LOW HIGH) with LOW < HIGH")
        if keyword in s.fixed:
            raise InputError(f"{where}: '{keyword}' is both fixed and tuned; expected one of the two")
        _check_limits(keyword, rng, f"{where}/parameters")
        s.parameters.append(Parameter(keyword, rng[0], rng[1]))
    targets = sd.get("targets")
    if not isinstance(targets, dict) or not targets:
        raise InputError(f"{where}: keyword 'targets' is missing or empty; expected e.g. "
                         f"targets {{ angleAt50PercentSlid {{ value 29; sigma 1.5; }} }}")
    known = known_result_keys(case)
    for key, td in targets.items():
        tw = f"{where}/targets/{key}"
        if not isinstance(td, dict):
            raise InputError(f"{tw}: expected {{ value V; sigma S; }}")
        _unknown_keys(td, ["value", "sigma"], tw)
        if known is not None and key not in known:
            raise InputError(f"{tw}: the case's post-processing does not report '{key}' in results.json; "
                             f"it reports: {', '.join(sorted(known))}")
        s.targets.append(Target(key, _number(td, "value", tw), _number(td, "sigma", tw, None, 1e-300)))
    d = len(s.parameters)
    if d == 0:
        s.initial_runs = s.min_runs = s.max_runs = 1
        s.tolerance = _number(sd, "tolerance", where, 1.0, 1e-6)
        return s
    s.start_run = _word(sd, "startRun", where, ("yes", "no"), "yes") == "yes"
    s.initial_runs = _number(sd, "initialRuns", where, max(4, 2 * d + 2), 2, None, True)
    s.min_runs = _number(sd, "minRuns", where, s.first_runs + 1, 1, None, True)
    s.max_runs = _number(sd, "maxRuns", where, max(4 * s.initial_runs + s.first_runs - s.initial_runs, s.min_runs),
                         1, None, True)
    if s.max_runs < s.first_runs:
        raise InputError(f"{where}: keyword 'maxRuns' is {s.max_runs}; expected at least the first sample's "
                         f"{s.first_runs} runs (initialRuns{' + the start run' if s.start_run else ''})")
    s.tolerance = _number(sd, "tolerance", where, 1.0, 1e-6)
    s.ei_tolerance = _number(sd, "eiTolerance", where, 0.01, 0.0)
    s.choose = _word(sd, "choose", where, ("nearest", "best"), "nearest")
    s.nearest_runs = _number(sd, "nearestRuns", where, 2 if s.choose == "nearest" else 0, 0, None, True)
    if s.nearest_runs and s.choose != "nearest":
        raise InputError(f"{where}: keyword 'nearestRuns' is {s.nearest_runs} with 'choose best'; expected 0, "
                         f"or 'choose nearest' (the runs are made to find the agreeing values nearest the case's)")
    return s


def _check_limits(keyword, values, where):
    last = keyword.split("/")[-1]
    for v in values:
        if not casefile.within_limits(last, v):
            raise InputError(f"{where}: '{keyword}' {'range reaches' if len(values) > 1 else 'is'} {v:g}, which the "
                             f"model does not accept; expected {last} {casefile.describe_limits(last)} "
                             f"(docs/case-reference.md)")
