"""How much of a student program's output goes where.

The sandbox keeps up to a budget of each program's output (its first and last halves, see
``autograder.sandbox.process.BoundedOutput``). Test messages are repeated by every results
format, once per test, so they carry only :func:`message_tail`: a few short lines of the end.
The whole kept output goes once into the HTML report and into a log file beside the results.

The pytest child writes each program's kept output to a file of its own beside the raw
report (:func:`log_folder`) when the program stops, and the signed report names each file
with its digest: the report, re-written after every test, stays small.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

from autograder.i18n import _, ngettext

# A test message's share of the output: the end, where the traceback is.
TAIL_LINES = 15
TAIL_BYTES = 2048
LINE_CHARS = 300
# The raw report's per-test log tail (the JUnit system-out and RunResult.log_tail).
LOG_TAIL_LINES = 40
LOG_TAIL_BYTES = 4000
# Whatever else a test puts in its message (data it received, a long repr) is cut too.
MESSAGE_BYTES = 8192
DETAILS_BYTES = 16384
CUT = "…"


def _utf8_len(text: str) -> int:
    return len(text.encode("utf-8", "replace"))


def _fit_bytes(text: str, limit: int) -> str:
    """``text`` cut at the end to ``limit`` UTF-8 bytes, marked when cut."""
    if _utf8_len(text) <= limit:
        return text
    room = max(0, limit - _utf8_len(CUT))
    return text.encode("utf-8", "replace")[:room].decode("utf-8", "ignore") + CUT


def clip_line(line: str, width: int = LINE_CHARS) -> str:
    """A line cut to ``width`` characters, with a visible mark where it was cut."""
    return line if len(line) <= width else line[: max(0, width - len(CUT))] + CUT


def message_tail(text: str, lines: int = TAIL_LINES, max_bytes: int = TAIL_BYTES,
                 line_chars: int = LINE_CHARS) -> str:
    """The last ``lines`` lines of ``text``, each cut to ``line_chars`` characters, and as
    many of them as fit in ``max_bytes`` (UTF-8, newlines included)."""
    kept: list[str] = []
    size = 0
    for line in reversed(text.rstrip().splitlines()[-lines:] if lines > 0 else []):
        line = clip_line(line, line_chars)
        cost = _utf8_len(line) + (1 if kept else 0)
        if size + cost > max_bytes:
            if not kept:  # a last line too long even alone still shows its start
                kept.append(_fit_bytes(line, max_bytes))
            break
        kept.append(line)
        size += cost
    return "\n".join(reversed(kept))


def size_note(total: int, budget: int) -> str:
    """Says how much a program wrote when that was more than the sandbox kept."""
    if total <= budget:
        return ""
    return ngettext("(Your program wrote {size} byte of output; only the first and last "
                    "{kept} bytes were kept.)",
                    "(Your program wrote {size} bytes of output; only the first and last "
                    "{kept} bytes were kept.)", total).format(size=total, kept=budget // 2)


def clip_middle(text: str, max_bytes: int) -> str:
    """``text`` in at most ``max_bytes``: its start and end, a mark between them."""
    if _utf8_len(text) <= max_bytes:
        return text
    half = (max_bytes - _utf8_len(f"\n{CUT}\n")) // 2  # the mark counts too
    start = _fit_bytes(text, half).removesuffix(CUT)
    raw_end = text.encode("utf-8", "replace")[-half:]
    return f"{start}\n{CUT}\n{raw_end.decode('utf-8', 'ignore')}"


def log_folder(report: Path) -> Path:
    """Where the pytest child writes each program's kept output, beside the raw report."""
    return report.with_name(report.stem + ".logs")


def log_beside(results: Path) -> Path:
    """The log file written beside a results file: ``results.json`` -> ``results.log``."""
    return results.with_suffix(".log") if results.suffix != ".log" else \
        results.with_name(results.name + ".log")


def digest(raw: bytes) -> str:
    return hashlib.sha256(raw).hexdigest()


def describe_exit(code: int) -> str:
    """How a program ended, from its exit status (negative: the signal that killed it)."""
    if code < 0:
        import signal

        try:
            return _("was killed by signal {name}").format(name=signal.Signals(-code).name)
        except ValueError:
            return _("was killed by signal {number}").format(number=-code)
    return _("exited with status {code}").format(code=code)
