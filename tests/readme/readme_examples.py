"""Every example of README.md, in order, as the runner (``run_readme.py``) and the fast checks
(``tests/python/test_readme_examples.py``) read them.

An example is one shell command (its continuation lines joined) or one Python block. Shell
blocks hold commands, comments and, in a transcript, ``$ COMMAND`` lines followed by the lines the
command prints. Each example keeps the claims its text makes that a run can check:

* ``--png F``, ``--snapshot F``, ``--out D``: the file or directory is written;
* an ``experiment NAME`` line: its directory gets ``summary.md``, ``results.sqlite`` and a PNG
  (a sweep: ``sweep.md``, ``sweep.csv``, ``sweep.png`` and ``results.sqlite``);
* a comment saying ``lifted`` (and not ``not lifted``): the command reports a lift;
* a transcript: the command prints exactly the lines shown.

Some examples cannot run here; :func:`not_run` says why (the two ``make`` commands, which run
this; ``view`` without ``--snapshot``, a server that waits for a browser). An example whose text
names a placeholder address (``HEAD:6379``) must be refused quickly, naming the option.
"""
from __future__ import annotations

import re
import shlex
from dataclasses import dataclass, field
from pathlib import Path
from typing import List, Optional

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"


@dataclass
class Example:
    """One example: ``kind`` "sh" or "python", its text, where it is (README line, section) and
    what its text claims."""

    kind: str
    text: str
    line: int
    section: str
    comment: str = ""
    printed: Optional[List[str]] = None          # a transcript's expected output
    claims: List[str] = field(default_factory=list)

    @property
    def argv(self) -> List[str]:
        return shlex.split(self.text) if self.kind == "sh" else []

    def label(self) -> str:
        first = self.text.strip().splitlines()[0]
        return f"README:{self.line} {first[:110]}"


def parse(text: Optional[str] = None) -> List[Example]:
    """The README's examples in order."""
    text = README.read_text() if text is None else text
    lines = text.splitlines()
    out: List[Example] = []
    section, i = "", 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("#") and not line.startswith("#!"):
            section = line.lstrip("#").strip()
        m = re.match(r"^```(sh|python)\s*$", line)
        if not m:
            i += 1
            continue
        start, j = i + 1, i + 1
        while not lines[j].startswith("```"):
            j += 1
        block = lines[start:j]
        if m.group(1) == "python":
            out.append(Example("python", "\n".join(block) + "\n", start + 1, section))
        else:
            out += _shell(block, start + 1, section)
        i = j + 1
    for e in out:
        e.claims = claims(e)
    return out


def _shell(block: List[str], first_line: int, section: str) -> List[Example]:
    out: List[Example] = []
    transcript = any(l.startswith("$ ") for l in block)
    k = 0
    while k < len(block):
        raw, line_no = block[k], first_line + k
        k += 1
        if transcript:
            if not raw.startswith("$ "):
                continue
            printed = []
            while k < len(block) and not block[k].startswith("$ "):
                printed.append(block[k])
                k += 1
            out.append(Example("sh", raw[2:], line_no, section, printed=printed))
            continue
        if not raw.strip() or raw.lstrip().startswith("#"):
            continue
        text = raw
        while _split_comment(text)[0].rstrip().endswith("\\") or _open_quote(_split_comment(text)[0]):
            cmd = _split_comment(text)[0].rstrip()
            text = (cmd[:-1] if cmd.endswith("\\") else cmd + "\n") + " " + block[k].strip()
            k += 1
        cmd, comment = _split_comment(text)
        # a comment line right before a command describes it when the command has none
        if not comment and line_no - first_line > 0 and block[line_no - first_line - 1].lstrip().startswith("#"):
            comment = block[line_no - first_line - 1].lstrip("# ").strip()
        out.append(Example("sh", cmd.strip(), line_no, section, comment=comment))
    return out


def _open_quote(text: str) -> bool:
    try:
        shlex.split(text)
        return False
    except ValueError:
        return True


def _split_comment(text: str):
    """(command, trailing comment): the first `` #`` outside quotes starts the comment."""
    quote = None
    for n, ch in enumerate(text):
        if quote:
            quote = None if ch == quote else quote
        elif ch in "'\"":
            quote = ch
        elif ch == "#" and (n == 0 or text[n - 1].isspace()):
            return text[:n], text[n + 1:].strip()
    return text, ""


def _option(argv: List[str], name: str) -> Optional[str]:
    for n, a in enumerate(argv):
        if a == name and n + 1 < len(argv):
            return argv[n + 1]
        if a.startswith(name + "="):
            return a.split("=", 1)[1]
    return None


def bayesgrasp_argv(e: Example) -> Optional[List[str]]:
    """The arguments after ``bayesgrasp`` of a command that runs it (its first command), else None."""
    if e.kind != "sh":
        return None
    argv = shlex.split(e.text.split("&&")[-1]) if "&&" in e.text else e.argv
    if not argv or not argv[0].endswith("bin/bayesgrasp"):
        return None
    for n, a in enumerate(argv):                 # up to a redirection or a pipe
        if a in (">", ">>", "|", "2>", "2>&1"):
            return argv[1:n]
    return argv[1:]


def experiment_out(argv: List[str]) -> Optional[str]:
    """An ``experiment NAME`` command's output directory (``--out``, else the default)."""
    if len(argv) < 2 or argv[0] != "experiment" or argv[1] == "list":
        return None
    return _option(argv, "--out") or f"out/experiments/{argv[1]}"


def claims(e: Example) -> List[str]:
    """What a run of ``e`` can be checked against (see the module's docstring)."""
    out: List[str] = []
    argv = bayesgrasp_argv(e) or []
    for opt in ("--png", "--snapshot"):
        f = _option(argv, opt)
        if f:
            out.append(f"file:{f}")
    if argv[:1] == ["experiment"] and not _option(argv, "--config") and experiment_out(argv):
        kind = "sweep" if "--sweep" in argv else "experiment"     # a sweep writes sweep.md/.csv/.png
        out.append(f"{kind}:{experiment_out(argv)}")
    elif _option(argv, "--out") and argv[:1] != ["experiment"]:
        out.append(f"dir:{_option(argv, '--out')}")
    if e.kind == "sh" and argv[:1] != ["experiment"] and e.argv[:1] == [".venv/bin/python"]:
        o = _option(e.argv, "--out")
        if o:
            out.append(f"dir:{o}")
    if re.search(r"\blifted\b", e.comment) and not re.search(r"not lifted", e.comment):
        out.append("lifted")
    if e.printed is not None:
        out.append("prints")
    if e.kind == "sh" and e.argv[:2] == ["make", "demo"]:
        out.append("dir:out/demo")
    return out


#: what ``make demo`` runs once the set-up is done (the Makefile's demo target)
MAKE_DEMO = ".venv/bin/bayesgrasp demo --out out/demo"


def not_run(e: Example) -> Optional[str]:
    """Why ``e`` is not run by the README runner, or None (``make demo`` runs as its job,
    :data:`MAKE_DEMO`)."""
    if e.kind == "sh" and e.argv[:1] == ["make"] and e.argv[1:2] != ["demo"]:
        return "the set-up command that runs this"
    argv = bayesgrasp_argv(e) or []
    if argv[:1] == ["view"] and "--snapshot" not in argv:
        return "a viewer server that waits for a browser"
    return None


def expects_refusal(e: Example) -> bool:
    """An example with a placeholder address: it must be refused in one line naming --address."""
    return "HEAD:6379" in e.text
