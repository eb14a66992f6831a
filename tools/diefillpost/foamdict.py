"""A reader for the subset of OpenFOAM dictionary syntax that demLib accepts
(docs/input-format.md): `key value;`, `key { ... }`, nested lists, comments,
`$name` copies and `#include "file"`.  Values become float (numbers), str (words,
quoted strings) or list; dictionaries become dict (insertion ordered)."""
import os
import re

_NUMBER = re.compile(r"^[+-]?\d+(\.\d*)?([eE][+-]?\d+)?$|^[+-]?\.\d+([eE][+-]?\d+)?$")
_TOKEN = re.compile(r'"(?:[^"\\]|\\.)*"|[{}();]|[^\s{}();"]+')


def _strip_comments(text):
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    return re.sub(r"//[^\n]*", " ", text)


def _tokens(text):
    return _TOKEN.findall(_strip_comments(text))


class _Parser:
    def __init__(self, path):
        self.path = path

    def parse_file(self, path, scopes):
        with open(path) as f:
            toks = _tokens(f.read())
        return self._parse_entries(toks, 0, scopes, os.path.dirname(path), top=True)[0]

    def _lookup(self, name, scopes):
        for scope in reversed(scopes):
            if name in scope:
                return scope[name]
        raise KeyError(f"{self.path}: '${name}' is not defined")

    def _value(self, tok, scopes):
        if tok.startswith("$"):
            return self._lookup(tok[1:], scopes)
        if tok.startswith('"'):
            return tok[1:-1].replace('\\"', '"').replace("\\\\", "\\")
        if _NUMBER.match(tok):
            return float(tok)
        return tok

    def _parse_item(self, toks, i, scopes):
        """One list element or entry value at toks[i]: a (nested) list or a scalar."""
        if toks[i] == "(":
            return self._parse_list(toks, i + 1, scopes)
        return self._value(toks[i], scopes), i + 1

    def _parse_list(self, toks, i, scopes):
        out = []
        while toks[i] != ")":
            item, i = self._parse_item(toks, i, scopes)
            out.append(item)
        return out, i + 1

    def _parse_entries(self, toks, i, scopes, base, top=False):
        d = {}
        scopes = scopes + [d]
        while i < len(toks):
            tok = toks[i]
            if tok == "}":
                return d, i + 1
            if tok == ";":
                i += 1
                continue
            if tok == "#include":
                inc = toks[i + 1][1:-1]
                d.update(self.parse_file(os.path.join(base, inc), scopes))
                i += 2
                continue
            key = tok
            i += 1
            if toks[i] == "{":
                sub, i = self._parse_entries(toks, i + 1, scopes, base)
                if not (top and key == "FoamFile"):
                    d[key] = sub
                continue
            values = []
            while toks[i] != ";":
                if toks[i] == "[":  # dimension sets are not tokenised separately; skip
                    i += 1
                    continue
                item, i = self._parse_item(toks, i, scopes)
                values.append(item)
            d[key] = values[-1] if values else None
            i += 1
        return d, i


def read(path):
    """Parse an OpenFOAM-style dictionary file into nested dicts."""
    return _Parser(path).parse_file(path, [])


def read_case(case_dir):
    """The case's constant/demProperties."""
    return read(os.path.join(case_dir, "constant", "demProperties"))
