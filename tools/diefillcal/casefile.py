"""Reading and setting one keyword of a case's constant/demProperties by its path
(`interactions/sand-steel/friction`), in the text itself, so that the comments and the
'// @quick' lines that a tutorial's Allrun swaps in stay as they are."""
import os
import re

from diefillpost import foamdict

# Accepted values, as docs/case-reference.md states them (demRun refuses anything else, but
# only when the run starts; checked here before a single run is made).
#   name: (low, high, low_open, high_open)
KEYWORD_LIMITS = {
    "friction": (0.0, None, False, False),
    "rollingFriction": (0.0, None, False, False),
    "restitution": (0.0, 1.0, True, False),
    "rollingViscousDamping": (0.0, None, False, False),
    "youngsModulus": (0.0, None, True, False),
    "poissonRatio": (0.0, 0.5, False, False),
    "density": (0.0, None, True, False),
}


def describe_limits(name):
    low, high, low_open, high_open = KEYWORD_LIMITS[name]
    if high is None:
        return f"{'above' if low_open else 'at least'} {low:g}"
    return f"in {'(' if low_open else '['}{low:g}, {high:g}{')' if high_open else ']'}"


def within_limits(name, value):
    if name not in KEYWORD_LIMITS:
        return True
    low, high, low_open, high_open = KEYWORD_LIMITS[name]
    if low is not None and (value < low or (low_open and value == low)):
        return False
    if high is not None and (value > high or (high_open and value == high)):
        return False
    return True


def _mask_comments(text):
    """The text with every comment replaced by spaces of the same length, so that
    positions found in it are positions in the original."""
    def blank(m):
        return re.sub(r"[^\n]", " ", m.group(0))
    text = re.sub(r"/\*.*?\*/", blank, text, flags=re.S)
    return re.sub(r"//[^\n]*", blank, text)


_TOKEN = re.compile(r'"(?:[^"\\]|\\.)*"|[{}();]|[^\s{}();"]+')


def _find_value_span(text, path):
    """(start, end) of the value of the scalar entry `key value;` at `path` (list of
    names) in `text`, or None when there is none."""
    tokens = [(m.group(0), m.start(), m.end()) for m in _TOKEN.finditer(_mask_comments(text))]
    stack = []          # names of the dictionaries open at token i
    i = 0
    while i < len(tokens):
        key = tokens[i][0]
        if key == "}":
            if stack:
                stack.pop()
            i += 1
        elif key == ";":
            i += 1
        elif key.startswith("#"):           # '#include "file"' has no ';'
            i += 2
        elif i + 1 < len(tokens) and tokens[i + 1][0] == "{":
            stack.append(key)
            i += 2
        else:
            j = i + 1                       # the value runs to the ';' outside any list
            depth = 0
            while j < len(tokens) and not (tokens[j][0] == ";" and depth == 0):
                depth += {"(": 1, ")": -1}.get(tokens[j][0], 0)
                j += 1
            if stack + [key] == list(path) and j == i + 2:
                return tokens[i + 1][1], tokens[i + 1][2]
            i = j + 1
    return None


def source_file(case):
    """The file a tutorial's Allrun makes constant/demProperties from: demProperties.orig once
    Allrun has run in the folder, demProperties before."""
    orig = os.path.join(case, "constant", "demProperties.orig")
    return orig if os.path.exists(orig) else os.path.join(case, "constant", "demProperties")


def read_value(path_in_file, keyword):
    """The number at `keyword` ('a/b/c') in the dictionary file, or a KeyError naming both."""
    names = keyword.split("/")
    d = foamdict.read(path_in_file)
    for n in names:
        if not isinstance(d, dict) or n not in d:
            raise KeyError(f"{path_in_file}: no keyword '{keyword}' ('{n}' not found); "
                           f"expected a path of dictionary names ending in a number, e.g. interactions/sand-steel/friction")
        d = d[n]
    if not isinstance(d, float):
        raise KeyError(f"{path_in_file}: keyword '{keyword}' is not a single number (found {d!r})")
    return d


def check_tunable(path_in_file, keyword):
    """A KeyError unless `keyword` is a number in the file on a line that the quick
    setting does not replace (a '// @quick' line would undo the change)."""
    read_value(path_in_file, keyword)
    with open(path_in_file) as f:
        text = f.read()
    span = _find_value_span(text, keyword.split("/"))
    if span is None:
        raise KeyError(f"{path_in_file}: keyword '{keyword}' could not be located in the text "
                       f"(written through '$' or #include?); give the keyword where its value is written")
    line_start = text.rfind("\n", 0, span[0]) + 1
    line_end = text.find("\n", span[0])
    line = text[line_start:line_end if line_end >= 0 else len(text)]
    if "// @quick" in line:
        raise KeyError(f"{path_in_file}: keyword '{keyword}' is on a line with a '// @quick' alternative, which the "
                       f"quick setting swaps in: a value set there would be lost; not tunable")


def set_values(path_in_file, values):
    """Writes each {keyword: number} into the file, keeping everything else; reads the
    file back and checks each value arrived."""
    with open(path_in_file) as f:
        text = f.read()
    for keyword, value in values.items():
        span = _find_value_span(text, keyword.split("/"))
        if span is None:
            raise KeyError(f"{path_in_file}: no keyword '{keyword}' to set")
        text = text[:span[0]] + f"{value:.10g}" + text[span[1]:]
    with open(path_in_file, "w") as f:
        f.write(text)
    for keyword, value in values.items():
        got = read_value(path_in_file, keyword)
        if abs(got - float(f"{value:.10g}")) > 1e-12 * max(1.0, abs(value)):
            raise ValueError(f"{path_in_file}: '{keyword}' reads {got!r} after it was set to {value!r}")
