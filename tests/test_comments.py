"""Comments and docstrings say why, not when: no comment in the product or the benchmarks
cites a numbered session, round or issue of past work (the history is in git log and
CHANGELOG.md; a figure is cited from the benchmark that measures it)."""

from __future__ import annotations

import io
import re
import tokenize
from pathlib import Path

from tests.paths import ROOT

FOLDERS = ("monopic", "sim", "bench", "tools", "studies")
# "session 12", "issues 17-18", "round 3"; not an option such as `--rounds 5`.
HISTORY = re.compile(r"(?<![-\w])(?:issues?|sessions?|rounds?)\s+#?\d+", re.IGNORECASE)


def comments_and_strings(path: Path) -> list[tuple[int, str]]:
    """(line, text) of every comment and string literal (docstrings included) of a file."""
    out = []
    tokens = tokenize.generate_tokens(io.StringIO(path.read_text(encoding="utf-8")).readline)
    for tok in tokens:
        if tok.type in (tokenize.COMMENT, tokenize.STRING):
            out.append((tok.start[0], tok.string))
    return out


def history_citations(folders: tuple[str, ...] = FOLDERS, root: Path = ROOT) -> list[str]:
    found = []
    for folder in folders:
        for path in sorted((root / folder).rglob("*.py")):
            for line, text in comments_and_strings(path):
                for match in HISTORY.finditer(text):
                    found.append(f"{path.relative_to(root)}:{line}: {match.group(0)!r}")
    return found


def test_no_comment_cites_a_numbered_session_round_or_issue():
    assert history_citations() == []


def test_the_check_finds_each_form_in_comments_and_docstrings(tmp_path):
    code = tmp_path / "pkg"
    code.mkdir()
    (code / "m.py").write_text(
        '"""Docstring (session 12)."""\n'
        "x = 1  # as issue 21 found\n"
        "y = 'rounds 3-4'\n"
        "z = '--rounds 5'  # an option\n"
        "issue_count = 2  # a name, not a citation: issue counts\n"
    )
    assert [f.split(": ", 1)[1] for f in history_citations(("pkg",), tmp_path)] == [
        "'session 12'", "'issue 21'", "'rounds 3'"
    ]  # fmt: skip
