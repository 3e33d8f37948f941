#!/usr/bin/env python3
"""Check that the documentation shows what the tool does (run by .ci/book).

Reads README.md, book/src/**/*.md and docs/conventions.md (or the files given) and
checks every fenced shell block and every relative link. Python 3 standard library only.

Every ```sh, ```bash, ```shell or ```console block must have a marker, an HTML comment
alone on the line just before its opening fence (blank lines may stand between them):

  <!-- check: output -->          a ```console block: each line starting with "$ " is a
                                  command (a line ending in " \\" continues on the next
                                  line), the lines up to the next "$ " line are what it
                                  prints, standard output and standard error together as
                                  a terminal shows them. The command must exit with 0 and
                                  print exactly those lines (trailing spaces and trailing
                                  blank lines aside). In an expected line, "…" matches any
                                  text within that line: use it only for what changes from
                                  run to run (a duration), never to hide a number that
                                  should stay put.
  <!-- check: output, exit N -->  the same, for commands that must exit with N.
  <!-- check: run -->             a ```sh block run as one bash script (set -euo pipefail);
                                  it must exit with 0. Its output is shown only on failure.
  <!-- check: repo -->            the same, run from the repository's root instead (cargo
                                  commands: the script builds nothing else there).
  <!-- check: skip: REASON -->    not run; REASON says why (a placeholder for the reader's
                                  own data, a command that CI runs elsewhere, a long run).

The "output" and "run" blocks of one page run in order in one temporary directory, new
for each page, in which the release CLI is on PATH as `inertia` (`target/release`) and
`telemetry.csv` (with `telemetry.truth.json`) already holds a simulated slew, so that a
page's own-file examples run as written. The Python examples are run by
crates/inertia-py/tests/test_readme.py (.ci/python), not here.

Links: every relative link and image target in the checked files must exist (anchors
are not checked), and so must every mdBook {{#include FILE}}.

Usage: python3 scripts/check_book.py [--inertia PATH] [--bless] [FILE.md ...]
Exit 0 when everything agrees; 1 otherwise, after listing every difference. With
--bless, an "output" block whose commands print something else is rewritten with what
they print (review the diff: a changed number is a changed result, to be explained).
"""

import argparse
import difflib
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SHELL_LANGS = {"sh", "bash", "shell", "console"}
MARKER = re.compile(r"^<!--\s*check:\s*(output|run|repo|skip)\b(.*?)-->\s*$")
FENCE = re.compile(r"^(\s*)(```+|~~~+)\s*([\w+-]*)")
TIMEOUT_S = 600


class Block:
    def __init__(self, path, line, lang, mode, option, text):
        self.path, self.line, self.lang = path, line, lang
        self.mode, self.option, self.text = mode, option, text

    def where(self):
        return f"{self.path.relative_to(ROOT)}:{self.line}"


def blocks(path):
    """Fenced blocks of a markdown file with the marker before each (or None)."""
    lines = path.read_text(encoding="utf-8").split("\n")
    out, i, marker = [], 0, None
    while i < len(lines):
        line = lines[i]
        m = FENCE.match(line)
        if m:
            indent, fence, lang = m.groups()
            body, j = [], i + 1
            while j < len(lines) and not lines[j].strip().startswith(fence):
                body.append(lines[j][len(indent):] if lines[j].startswith(indent) else lines[j])
                j += 1
            mode, option = marker if marker else (None, "")
            out.append(Block(path, i + 1, lang.lower(), mode, option, "\n".join(body)))
            marker, i = None, j + 1
            continue
        mk = MARKER.match(line.strip())
        if mk:
            marker = (mk.group(1), mk.group(2).strip().lstrip(",:").strip())
        elif line.strip():
            marker = None
        i += 1
    return out


def console_steps(text, raw=False):
    """[(command, [expected lines])] of a console block (with `raw`, each step's command
    lines as written, continuations included, as a third element)."""
    steps, lines = [], text.split("\n")
    k = 0
    while k < len(lines):
        if not lines[k].startswith("$ "):
            if lines[k].strip():
                raise ValueError(f"output before the first `$ ` command: {lines[k]!r}")
            k += 1
            continue
        cmd, first = lines[k][2:], k
        while cmd.endswith("\\") and k + 1 < len(lines):
            k += 1
            cmd = cmd[:-1] + lines[k]
        k += 1
        written = lines[first:k]
        expected = []
        while k < len(lines) and not lines[k].startswith("$ "):
            expected.append(lines[k])
            k += 1
        steps.append((cmd, expected, written) if raw else (cmd, expected))
    return steps


def normalise(lines):
    lines = [l.rstrip() for l in lines]
    while lines and not lines[-1]:
        lines.pop()
    return lines


def line_matches(expected, actual):
    if "…" not in expected:
        return expected == actual
    pattern = ".*".join(re.escape(part) for part in expected.split("…"))
    return re.fullmatch(pattern, actual) is not None


def outputs_agree(expected, actual):
    return len(expected) == len(actual) and all(line_matches(e, a) for e, a in zip(expected, actual))


def run(cmd, cwd, env):
    p = subprocess.run(
        ["bash", "-c", cmd], cwd=cwd, env=env, stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT, timeout=TIMEOUT_S,
    )
    return p.returncode, p.stdout.decode("utf-8", "replace")


def check_links(path, problems):
    text = path.read_text(encoding="utf-8")
    # Links outside code: drop fenced blocks and inline code first.
    text = re.sub(r"```.*?```", "", text, flags=re.S)
    text = re.sub(r"`[^`\n]*`", "", text)
    for target in re.findall(r"\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)", text):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith("#"):
            continue
        file = target.split("#", 1)[0]
        if file and not (path.parent / file).exists():
            problems.append(f"{path.relative_to(ROOT)}: broken link `{target}`")
    for target in re.findall(r"\{\{#include\s+([^}:\s]+)", path.read_text(encoding="utf-8")):
        if not (path.parent / target).exists():
            problems.append(f"{path.relative_to(ROOT)}: {{{{#include {target}}}}} does not exist")


def bless(path, rewrites):
    """Replace the bodies of the blocks of `path` in `rewrites` (block, new body lines),
    keeping each block's indentation."""
    if not rewrites:
        return
    lines = path.read_text(encoding="utf-8").split("\n")
    for b, body in sorted(rewrites, key=lambda r: -r[0].line):
        start = b.line  # the fence is line b.line (1-based): the body starts after it
        indent = FENCE.match(lines[start - 1]).group(1)
        end = start
        while not lines[end].strip().startswith(FENCE.match(lines[start - 1]).group(2)):
            end += 1
        lines[start:end] = [indent + l if l else l for l in body]
    path.write_text("\n".join(lines), encoding="utf-8")
    print(f"blessed {len(rewrites)} block(s) of {path.relative_to(ROOT)}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--inertia", default=str(ROOT / "target" / "release" / "inertia"))
    ap.add_argument("--bless", action="store_true",
                    help="rewrite the output blocks that disagree with what the tool prints")
    ap.add_argument("files", nargs="*")
    args = ap.parse_args()
    files = [Path(f).resolve() for f in args.files] or (
        [ROOT / "README.md"] + sorted((ROOT / "book" / "src").rglob("*.md")) + [ROOT / "docs" / "conventions.md"]
    )
    inertia = Path(args.inertia).resolve()
    if not os.access(inertia, os.X_OK):
        sys.exit(f"check_book: no CLI at {inertia} (cargo build --release -p inertia-cli)")
    bindir = Path(tempfile.mkdtemp(prefix="check-book-bin-"))
    (bindir / "inertia").symlink_to(inertia)
    env = dict(os.environ, PATH=f"{bindir}{os.pathsep}{os.environ.get('PATH', '')}",
               LC_ALL="C.UTF-8", NO_COLOR="1")

    problems, counts = [], {"output": 0, "commands": 0, "run": 0, "repo": 0, "skip": 0}
    rewrites = []
    passed = failed = 0
    for path in files:
        check_links(path, problems)
        work = None
        for b in blocks(path):
            if b.lang not in SHELL_LANGS:
                continue
            if b.mode is None:
                problems.append(f"{b.where()}: a ```{b.lang} block without a <!-- check: … --> marker")
                failed += 1
                continue
            if b.mode == "skip":
                counts["skip"] += 1
                if not b.option:
                    problems.append(f"{b.where()}: `check: skip` needs a reason")
                    failed += 1
                continue
            if b.mode in ("output", "run") and work is None:
                work = Path(tempfile.mkdtemp(prefix="check-book-"))
                code, out = run("inertia simulate --scenario slew -o telemetry.csv", work, env)
                if code != 0:
                    sys.exit(f"check_book: cannot simulate telemetry.csv:\n{out}")
            ok = True
            if b.mode == "output":
                if b.lang != "console":
                    problems.append(f"{b.where()}: `check: output` goes before a ```console block")
                    failed += 1
                    continue
                want_exit = 0
                m = re.fullmatch(r"exit\s+(\d+)", b.option)
                if m:
                    want_exit = int(m.group(1))
                elif b.option:
                    problems.append(f"{b.where()}: unknown option `{b.option}`")
                try:
                    steps = console_steps(b.text)
                except ValueError as e:
                    problems.append(f"{b.where()}: {e}")
                    failed += 1
                    continue
                counts["output"] += 1
                blessed, changed = [], False
                for cmd, expected, written in console_steps(b.text, raw=True):
                    counts["commands"] += 1
                    code, out = run(cmd, work, env)
                    expected, actual = normalise(expected), normalise(out.split("\n"))
                    agree = outputs_agree(expected, actual)
                    blessed += written + (expected if agree else actual)
                    if code != want_exit:
                        problems.append(f"{b.where()}: `$ {cmd}` exited with {code}, not {want_exit}:\n{out}")
                        ok = False
                    elif not agree:
                        diff = "\n".join(difflib.unified_diff(expected, actual, "the book", "the tool", lineterm=""))
                        if args.bless:
                            changed = True
                        else:
                            problems.append(f"{b.where()}: `$ {cmd}` printed something else:\n{diff}")
                            ok = False
                if changed:
                    rewrites.append((b, blessed))
            else:
                counts[b.mode] += 1
                script = "set -euo pipefail\n" + b.text
                code, out = run(script, ROOT if b.mode == "repo" else work, env)
                if code != 0:
                    problems.append(f"{b.where()}: the block exited with {code}:\n{out}")
                    ok = False
            print(f"{'ok  ' if ok else 'FAIL'} {b.where()} ({b.mode})", flush=True)
            passed += ok
            failed += not ok
        if work is not None:
            shutil.rmtree(work, ignore_errors=True)
        bless(path, [r for r in rewrites if r[0].path == path])
    shutil.rmtree(bindir, ignore_errors=True)

    for p in problems:
        print(f"\n{p}", file=sys.stderr)
    print(
        f"\ncheck_book: {len(files)} files; {counts['output']} output blocks ({counts['commands']} commands "
        f"compared), {counts['run']} blocks run in a scratch directory, {counts['repo']} in the repository, "
        f"{counts['skip']} skipped with a reason; links {'ok' if not any('link' in p or 'include' in p for p in problems) else 'BROKEN'}"
    )
    print(f"book examples: {passed} passed, {failed} failed")
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
