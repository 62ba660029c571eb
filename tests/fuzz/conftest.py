"""Print how many bad inputs each class of the suite tried (issue 16 asks for the counts)."""

from __future__ import annotations

from fuzzkit import TRIED


def pytest_terminal_summary(terminalreporter):
    if TRIED:
        terminalreporter.write_sep("-", "bad inputs tried per class (issue 16)")
        for name, n in sorted(TRIED.items()):
            terminalreporter.write_line(f"{name:<46} {n:>6}")
        terminalreporter.write_line(f"{'total':<46} {sum(TRIED.values()):>6}")
