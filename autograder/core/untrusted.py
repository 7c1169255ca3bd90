"""Text a student's program wrote, made safe to show in a terminal, a CI log or an XML file.

A program's output is carried into test messages and logs, and from there into every
results format. Shown as written, an escape sequence clears the student's screen or sets
its title, a bidi override reorders a line, and NUL, BEL or ESC make JUnit XML not
well-formed. :func:`visible` shows each such character as an escape instead (``\\x1b``,
``\\u202e``): the text reads the same, and can do nothing but be read.
"""

from __future__ import annotations

import re

# Every character that acts instead of showing, or that XML 1.0 cannot hold:
_UNSAFE = (
    "\x00-\x08\x0b-\x1f\x7f-\x9f"  # C0 but tab and newline (a lone CR too), DEL, C1
    "\u061c\u200e\u200f\u202a-\u202e\u2066-\u2069"  # bidi marks, embeddings, isolates
    # Every other invisible format character (they hide text, or lay it out otherwise):
    # soft hyphen, zero width space, word joiner and invisible operators, deprecated
    # format controls, BOM, interlinear annotation, hieroglyph, shorthand and musical
    # format controls, tags. Not the joiners U+200C and U+200D (Urdu and emoji need them),
    # nor the visible number signs of Arabic and other scripts (U+0600-U+0605, ...).
    "\u00ad\u180e\u200b\u2060-\u2064\u206a-\u206f\ufeff\ufff9-\ufffb"
    "\U00013430-\U0001343f\U0001bca0-\U0001bca3\U0001d173-\U0001d17a\U000e0000-\U000e007f"
    "\u2028\u2029"  # line and paragraph separators: a line break that is not one
    "\ud800-\udfff\ufffe\uffff"  # not XML 1.0 characters
)
_FOUND = re.compile(f"\r\n|[{_UNSAFE}]")


def _escape(match: re.Match[str]) -> str:
    char = match.group(0)
    if char == "\r\n":
        return "\n"
    if char == "\r":
        return "\\r"
    code = ord(char)
    return f"\\x{code:02x}" if code < 0x100 else \
        f"\\u{code:04x}" if code < 0x10000 else f"\\U{code:08x}"


def visible(text: str) -> str:
    """``text`` with every control character but newline and tab, every bidi control and
    invisible format character shown as an escape (``\\x1b``, ``\\r``, ``\\u202e``); a
    CR LF is a newline. Printable text in any script is left as it is. Idempotent."""
    return _FOUND.sub(_escape, text)
