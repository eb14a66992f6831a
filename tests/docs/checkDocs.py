#!/usr/bin/env python3
"""checkDocs.py: checks of the manual that Sphinx does not make (tests/docs/run calls it).

    checkDocs.py links [-root DIR] [FILE.md ...]
        every relative link of the pages (default: the pages of the site, docs/conf.py's
        include_patterns) resolves: the file exists in the repository and, for a link to a
        heading of a Markdown page (page.md#anchor or #anchor), the heading exists.
    checkDocs.py commands [-root DIR] [FILE.md]
        every command in a shell code block (```sh, bash, shell, console) of the page
        (default: docs/user-guide.md) exists and its -help runs with exit status 0; for the
        project's own commands every option shown (-word) is named in that help text.
    checkDocs.py words [-root DIR] [FILE.md ...]
        no page speaks of sessions or of the development machines (history is dated by
        build and date, docs/performance.md).
    checkDocs.py layout [-root DIR]
        the README's status table has one line per figure, each naming where it is measured
        (a link or a path), no cell a paragraph; docs/performance.md shows the figures against
        LIGGGHTS with the machine, date and build in its first screen.

Prints one line per failure and 'checkDocs <what>: N checked, M failed'; exits 1 on a failure.
"""
import fnmatch
import glob
import os
import re
import shlex
import subprocess
import sys
import unicodedata

HELP_TIMEOUT = 60

# ------------------------------------------------------------------ the pages
def site_pages(root):
    """The Markdown pages of the site, as docs/conf.py's include_patterns name them."""
    conf = {}
    with open(os.path.join(root, "docs", "conf.py")) as f:
        exec(compile(f.read(), "docs/conf.py", "exec"), conf)
    pages = set()
    for pattern in conf["include_patterns"]:
        for path in glob.glob(os.path.join(root, pattern), recursive=True):
            rel = os.path.relpath(path, root)
            if not any(fnmatch.fnmatch(rel, p) or rel.startswith(p.rstrip("/") + "/")
                       for p in conf.get("exclude_patterns", [])):
                pages.add(path)
    return sorted(pages)


def strip_code(text):
    """The text with fenced code blocks and inline code replaced by blanks (line numbers kept)."""
    out, fence = [], None
    for line in text.split("\n"):
        m = re.match(r"^\s*(```+|~~~+)", line)
        if fence is None and m:
            fence = m.group(1)
            out.append("")
            continue
        if fence is not None:
            if line.strip().startswith(fence) and line.strip().strip(fence[0]) == "":
                fence = None
            out.append("")
            continue
        if re.match(r"^(    |\t)", line) and (not out or out[-1].strip() == ""
                                                or re.match(r"^(    |\t)", out[-1] or "")):
            # An indented code block (after a blank line): not Markdown.
            out.append("")
            continue
        out.append(re.sub(r"``[^`]*``|`[^`]*`", lambda m: " " * len(m.group(0)), line))
    return out


def slug(heading):
    """The anchor MyST (myst_heading_anchors) gives a heading: GitHub's rule."""
    text = re.sub(r"`([^`]*)`", r"\1", heading.strip())
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)      # link text only
    text = text.lower()
    text = "".join(c for c in text if c in " -_" or unicodedata.category(c)[0] in "LN")
    return text.replace(" ", "-")


def anchors(path):
    found, fence = set(), False
    with open(path, encoding="utf-8") as f:
        for line in f:
            if re.match(r"^\s*(```|~~~)", line):
                fence = not fence
                continue
            m = None if fence else re.match(r"^(#{1,6})\s+(.*?)\s*#*\s*$", line)
            if m:
                base, n = slug(m.group(2)), 0
                a = base
                while a in found:
                    n += 1
                    a = f"{base}-{n}"
                found.add(a)
    return found


LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")


def check_links(root, pages):
    checked = failed = 0
    root = os.path.realpath(root)
    for page in pages:
        with open(page, encoding="utf-8") as f:
            lines = strip_code(f.read())
        for number, line in enumerate(lines, 1):
            for m in LINK.finditer(line):
                target = m.group(1)
                if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I):   # http:, mailto:, ...
                    continue
                checked += 1
                where = f"{os.path.relpath(page, root)}:{number}"
                path, _, anchor = target.partition("#")
                dest = os.path.realpath(os.path.join(os.path.dirname(page), path)) if path else page
                if not dest.startswith(root + os.sep) and dest != root:
                    print(f"FAIL link {where}: {target} leaves the repository")
                    failed += 1
                elif not os.path.exists(dest):
                    print(f"FAIL link {where}: {target}: no such file ({os.path.relpath(dest, root)})")
                    failed += 1
                elif anchor and dest.endswith(".md") and anchor not in anchors(dest):
                    print(f"FAIL link {where}: {target}: {os.path.relpath(dest, root)} has no heading "
                          f"with the anchor #{anchor}")
                    failed += 1
    print(f"checkDocs links: {checked} checked, {failed} failed")
    return failed == 0


# --------------------------------------------------------------- the commands
SHELL_BLOCKS = {"sh", "bash", "shell", "console"}
# Commands of the shell and of the base system: that they exist is enough (`type`).
SYSTEM = {"cd", "source", ".", "cp", "ls", "cat", "less", "head", "tail", "grep", "export",
          "mkdir", "rm", "mv", "echo", "diff", "column", "date", "nproc", "sed", "awk", "du",
          "tar", "time", "sort", "python3", "xdg-open"}


def shell_blocks(path):
    """[(line number, text)] of the commands in the page's shell code blocks."""
    commands, block, start, buf = [], None, 0, ""
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            m = re.match(r"^\s*```+\s*([A-Za-z]*)", line)
            if m and block is None:
                block = m.group(1).lower()
                continue
            if block is not None and line.strip().startswith("```"):
                block = None
                continue
            if block not in SHELL_BLOCKS:
                continue
            text = line.rstrip("\n")
            if block == "console":
                if not text.startswith("$ ") and not buf:
                    continue                              # output shown after a command
                text = text[2:] if text.startswith("$ ") else text
            if not buf:
                start = number
            if text.rstrip().endswith("\\"):
                buf += text.rstrip()[:-1] + " "
                continue
            buf += text
            if buf.strip():
                commands.append((start, buf))
            buf = ""
    return commands


def simple_commands(text):
    """The simple commands of one line, comments removed, split at ; && || |."""
    try:
        lexer = shlex.shlex(text, posix=True, punctuation_chars=";&|")
        lexer.whitespace_split = True
        lexer.commenters = "#"
        tokens = list(lexer)
    except ValueError as error:
        raise ValueError(f"cannot parse '{text}': {error}")
    parts, current = [], []
    for token in tokens:
        if token and set(token) <= set(";&|"):
            if current:
                parts.append(current)
            current = []
        else:
            current.append(token)
    if current:
        parts.append(current)
    return parts


def check_commands(root, page):
    root = os.path.realpath(root)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    cwd = root                  # the guide's blocks start in the repository root
    copies = {}                 # a copy made by cp -r SRC DEST: DEST stands for SRC
    # The top-level ./Allrun copies tutorials/NAME to run/NAME.
    for case in glob.glob(os.path.join(root, "tutorials", "*")) + \
            glob.glob(os.path.join(root, "tutorials", "*", "*")):
        copies[os.path.join(root, "run", os.path.relpath(case, os.path.join(root, "tutorials")))] = case
    checked = failed = 0
    seen = set()

    def resolve(path, base):
        path = os.path.expanduser(path)
        full = os.path.normpath(path if os.path.isabs(path) else os.path.join(base, path))
        for dest in sorted(copies, key=len, reverse=True):
            if full == dest or full.startswith(dest + os.sep):
                return os.path.normpath(copies[dest] + full[len(dest):])
        return full

    for number, text in shell_blocks(page):
        where = f"{os.path.relpath(page, root)}:{number}"
        try:
            parts = simple_commands(text)
        except ValueError as error:
            print(f"FAIL command {where}: {error}")
            failed += 1
            continue
        for words in parts:
            while words and re.match(r"^[A-Za-z_][A-Za-z0-9_]*=", words[0]):
                words = words[1:]                        # VAR=value command ...
            if not words:
                continue
            name = words[0]
            if name in ("$DIEFILL_PYTHON", "${DIEFILL_PYTHON}"):
                words = words[1:]
                name = words[0] if words else name
            # etc/bashrc exports DIEFILL_DIR, the checkout: the guide's way back to it.
            words = [re.sub(r"^\$(DIEFILL_DIR\b|\{DIEFILL_DIR\})", lambda m: root, w) for w in words]
            name = words[0]
            if name == "cd":
                target = words[1] if len(words) > 1 else "~"
                cwd = resolve(target, cwd)
                continue
            if name == "cp" and "-r" in words and len(words) >= 4:
                src, dest = words[-2], words[-1]
                copies[os.path.normpath(os.path.join(cwd, os.path.expanduser(dest)))] = resolve(src, cwd)
            if name in SYSTEM:
                key = ("system", name)
                if key in seen:
                    continue
                seen.add(key)
                checked += 1
                found = subprocess.run(["bash", "-c", f"type {shlex.quote(name)}"],
                                       capture_output=True, env=env).returncode == 0
                if not found:
                    print(f"FAIL command {where}: '{name}' is not a command here")
                    failed += 1
                continue
            # A program: a path (./Allrun, tutorials/x/Allrun, tools/y.py) or on PATH.
            if "/" in name:
                program = resolve(name, cwd)
                if not os.path.isfile(program):
                    print(f"FAIL command {where}: {name}: no such file "
                          f"({os.path.relpath(program, root)})")
                    failed += 1
                    checked += 1
                    continue
                # A script without its executable bit runs as `$DIEFILL_PYTHON script`.
                argv = [program] if os.access(program, os.X_OK) else \
                    [os.environ.get("DIEFILL_PYTHON", sys.executable), program]
            else:
                found = subprocess.run(["bash", "-c", f"command -v {shlex.quote(name)}"],
                                       capture_output=True, text=True, env=env)
                if found.returncode != 0:
                    print(f"FAIL command {where}: '{name}' is not on PATH (source etc/bashrc?)")
                    failed += 1
                    checked += 1
                    continue
                program = os.path.realpath(found.stdout.strip())
                argv = [name]
            options = sorted({w for w in words[1:] if re.match(r"^-[A-Za-z][A-Za-z-]*$", w)})
            key = (program, tuple(options))
            if key in seen:
                continue
            seen.add(key)
            checked += 1
            try:
                run = subprocess.run(argv + ["-help"], capture_output=True, text=True, env=env,
                                     cwd=os.path.dirname(program) if "/" in name else root,
                                     timeout=HELP_TIMEOUT, stdin=subprocess.DEVNULL)
            except subprocess.TimeoutExpired:
                print(f"FAIL command {where}: '{name} -help' ran longer than {HELP_TIMEOUT} s")
                failed += 1
                continue
            if run.returncode != 0:
                print(f"FAIL command {where}: '{name} -help' exited with {run.returncode}: "
                      f"{(run.stderr or run.stdout).strip().splitlines()[-1:] }")
                failed += 1
                continue
            ours = program.startswith(root + os.sep) and \
                not program.startswith(os.path.join(root, "ThirdParty") + os.sep)
            if ours:
                helptext = run.stdout + run.stderr
                unknown = [o for o in options
                           if not re.search(r"(^|[\s\[|(,])" + re.escape(o) + r"($|[\s\]|),=])",
                                            helptext, re.M)]
                if unknown:
                    print(f"FAIL command {where}: '{name} -help' does not name {' '.join(unknown)}")
                    failed += 1
    print(f"checkDocs commands: {checked} checked, {failed} failed")
    return failed == 0


# ------------------------------------------------------------------ the words
WORDS = re.compile(r"\bsessions?\b|this machine|the machine came|development machine|"
                   r"this workplace|the agents?\b", re.I)


def check_words(root, pages):
    failed = 0
    for page in pages:
        with open(page, encoding="utf-8") as f:
            for number, line in enumerate(f, 1):
                for m in WORDS.finditer(line):
                    print(f"FAIL words {os.path.relpath(page, root)}:{number}: '{m.group(0)}'")
                    failed += 1
    print(f"checkDocs words: {len(pages)} pages checked, {failed} failed (mentions)")
    return failed == 0


# ----------------------------------------------------------------- the layout
FIRST_SCREEN = 25        # lines of a page a reader sees first
LONGEST_CELL = 320       # characters: a table cell, not a paragraph


def check_layout(root):
    """The README's status table: one line per figure, each naming where it is measured, no
    paragraphs; docs/performance.md: the figures against LIGGGHTS, with the machines they
    were measured on, within the first screen."""
    failed = 0
    readme = os.path.join(root, "README.md")
    with open(readme, encoding="utf-8") as f:
        lines = f.read().split("\n")
    try:
        start = next(i for i, l in enumerate(lines) if re.match(r"^## Where it stands", l))
    except StopIteration:
        print("FAIL layout README.md: no section '## Where it stands'")
        return False
    rows = []
    for number in range(start + 1, len(lines)):
        line = lines[number]
        if line.startswith("## "):
            break
        if line.startswith("|") and not re.match(r"^\|[-| :]+\|$", line):
            rows.append((number + 1, [c.strip() for c in line.strip().strip("|").split("|")]))
    if len(rows) < 2:
        print("FAIL layout README.md: the status table has no rows")
        failed += 1
    header = rows[0][1] if rows else []
    for number, cells in rows[1:]:
        where = cells[-1] if cells else ""
        if len(cells) != len(header):
            print(f"FAIL layout README.md:{number}: {len(cells)} cells, the header has {len(header)}")
            failed += 1
        if not re.search(r"\]\(|`[^`]*/|`[^`]*\.md`", where):
            print(f"FAIL layout README.md:{number}: the last cell does not name where it is measured "
                  f"(a link or a path): '{where}'")
            failed += 1
        for cell in cells:
            if len(cell) > LONGEST_CELL:
                print(f"FAIL layout README.md:{number}: a cell of {len(cell)} characters "
                      f"(a paragraph; at most {LONGEST_CELL}): '{cell[:60]}...'")
                failed += 1
    with open(os.path.join(root, "docs", "performance.md"), encoding="utf-8") as f:
        screen = "".join(f.readlines()[:FIRST_SCREEN])
    for what, pattern in (("a table of the figures", r"^\|.*\|$"), ("LIGGGHTS", r"LIGGGHTS"),
                          ("the machines (a VM and its cores)", r"VM, \d+ cores"),
                          ("a date", r"\d{4}-\d\d-\d\d"), ("a build", r"build[s]? [0-9a-f]{7}")):
        if not re.search(pattern, screen, re.M):
            print(f"FAIL layout docs/performance.md: its first {FIRST_SCREEN} lines lack {what}")
            failed += 1
    print(f"checkDocs layout: {len(rows) - 1} status rows and performance.md's first screen checked, "
          f"{failed} failed")
    return failed == 0


def main(argv):
    if not argv or argv[0] in ("-h", "-help", "--help"):
        print(__doc__.strip())
        return 0 if argv else 2
    what, args = argv[0], argv[1:]
    root = os.path.realpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
    if args[:1] == ["-root"]:
        root, args = os.path.realpath(args[1]), args[2:]
    files = [os.path.abspath(a) for a in args]
    if what == "links":
        return 0 if check_links(root, files or site_pages(root)) else 1
    if what == "commands":
        return 0 if check_commands(root, files[0] if files else
                                   os.path.join(root, "docs", "user-guide.md")) else 1
    if what == "layout":
        return 0 if check_layout(root) else 1
    if what == "words":
        return 0 if check_words(root, files or site_pages(root)) else 1
    print(f"checkDocs.py: unknown check '{what}' (links, commands, words, layout)", file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
