"""Is the student's file a node Python runs? Checked in the grader's process, in
milliseconds, before any world starts, so that a file ``python FILE`` would refuse is
never graded and a file that is not a node is named plainly.

The node file must be a ``.py`` file that is not empty, decode as ``python FILE`` decodes
it (UTF-8, PEP 3120, unless a PEP 263 coding cookie says otherwise: decoded strictly here,
because ``compile(bytes)`` on Python 3.11 lets a bad byte in a comment through), compile
as ``python FILE`` compiles it (no ``__future__`` flags of ours), and create a node.

The rule for "creates a node", read from the syntax tree and never run: the node file or
a ``.py`` module beside it (the node may live in one it imports) imports from ``rclpy``
a name ending in ``Node`` or ``create_node`` (``from rclpy.node import Node``, also
``LifecycleNode`` or ``*``), or names an attribute ``Node``, ``...Node`` or
``create_node`` (``rclpy.node.Node``, ``rclpy.create_node``). It is deliberately loose:
it refuses a file that cannot make a node, never a node written in an unusual way.
"""

from __future__ import annotations

import ast
import io
import tokenize
import traceback
from collections.abc import Mapping

from autograder.i18n import _


class SourceRefused(ValueError):
    """The file is not a node Python runs; the message is for the student, as it stands."""


class SourceSyntaxError(SourceRefused):
    """The file does not compile; the message ends with Python's own lines (source line
    and caret)."""


def check_source(files: Mapping[str, bytes], filename: str, shown: str) -> str:
    """The node file's text, checked; ``files`` are the staged files by name (the node
    file under ``filename``), ``shown`` the path the student gave, as messages name it.
    Raises :class:`SourceRefused` (or :class:`SourceSyntaxError`) with one sentence."""
    if not shown.endswith(".py"):
        raise SourceRefused(_not_python(shown, filename))
    data = files[filename]
    if not data.strip():
        raise SourceRefused(_("{file} is empty: submit your node's code.").format(file=shown))
    text = _decode(data, shown)
    _compile(text, shown)
    if not any(_makes_node(source) for source in _texts(files, filename, text)):
        raise SourceRefused(_(
            "{file} creates no ROS node: neither it nor a module beside it subclasses "
            "rclpy's `Node` or calls `rclpy.create_node`.").format(file=shown))
    return text


def _not_python(shown: str, filename: str) -> str:
    """Why ``shown`` is no node file: a README, or not a ``.py`` file; naming the file to
    give instead when the exercise names one (``filename``)."""
    readme = shown.rpartition("/")[2].lower().startswith("readme")
    if not filename.endswith(".py"):  # a hand run of a file of any name
        return (_("{file} is a README, not your node: give your node's .py file.") if readme
                else _("{file} is not a Python file: give your node's .py file.")
                ).format(file=shown)
    return (_("{file} is a README, not your node: submit {expected}.") if readme
            else _("{file} is not a Python file: submit your node, {expected}.")
            ).format(file=shown, expected=filename)


def _decode(data: bytes, shown: str) -> str:
    """``data`` decoded as ``python FILE`` decodes it: a BOM or a coding cookie, else
    UTF-8; strictly, every line, comments too."""
    try:
        encoding, _lines = tokenize.detect_encoding(io.BytesIO(data).readline)
    except SyntaxError as exc:  # an unknown or contradictory coding cookie
        raise SourceSyntaxError(_syntax_message(exc, shown)) from None
    try:
        return data.decode(encoding)
    except UnicodeDecodeError as exc:
        raise SourceRefused(_(
            "{file}, line {line}: the byte {byte} is not {encoding}, so `python {file}` "
            "refuses the file: save it as UTF-8.").format(
            file=shown, line=data[:exc.start].count(b"\n") + 1,
            byte=f"0x{data[exc.start]:02x}", encoding=encoding.upper())) from None


def _compile(text: str, shown: str) -> None:
    """Compile as ``python FILE`` does (``dont_inherit``: none of our ``__future__``
    flags); a syntax error raises :class:`SourceSyntaxError` with Python's own lines."""
    if "\0" in text:
        raise SourceRefused(_(
            "{file}, line {line}: the file holds a NUL byte, so it is not Python source.")
            .format(file=shown, line=text[:text.index("\0")].count("\n") + 1))
    try:
        compile(text, shown, "exec", dont_inherit=True)
    except SyntaxError as exc:  # IndentationError and TabError too
        raise SourceSyntaxError(_syntax_message(exc, shown)) from None


def _syntax_message(exc: SyntaxError, shown: str) -> str:
    """One sentence, then the error as Python prints it (file, line, source, caret)."""
    return "\n".join((
        _("{file} does not compile, so Python cannot run it:").format(file=shown),
        "".join(traceback.format_exception_only(exc)).rstrip("\n")))


def _texts(files: Mapping[str, bytes], filename: str, text: str) -> list[str]:
    """The node file's text first, then each sibling module's (undecodable ones left out:
    Python only reads a module it imports)."""
    texts = [text]
    for name, data in files.items():
        if name != filename:
            try:
                texts.append(data.decode("utf-8"))
            except UnicodeDecodeError:
                continue
    return texts


def _makes_node(text: str) -> bool:
    """The rule of the module docstring, on one file (False if it does not parse)."""
    try:
        tree = ast.parse(text)
    except (SyntaxError, ValueError):
        return False
    for item in ast.walk(tree):
        if isinstance(item, ast.ImportFrom) and (item.module or "").split(".")[0] == "rclpy":
            if any(_node_name(alias.name) or alias.name == "*" for alias in item.names):
                return True
        elif isinstance(item, ast.Attribute) and _node_name(item.attr):
            return True
    return False


def _node_name(name: str) -> bool:
    return name.endswith("Node") or name == "create_node"
