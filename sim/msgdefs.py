"""ROS 2 message definitions as rosbag2 stores them in a bag: a type's full text with its
dependencies, and its type hash.

The text is read from the ``.msg`` files an installed interface package keeps in
``share/<pkg>/msg/`` and joined the way rosbag2's ``LocalMessageDefinitionSource`` joins
it (each dependency once, depth first, after a line of 80 ``=`` and ``MSG: pkg/Type``),
so MCAP readers (Foxglove, Lichtblick, ``mcap_ros2``) can decode the messages.  The hash
(REP 2011, ``RIHS01_...``) comes from the ``.json`` type description beside the ``.msg``.
``tf2_msgs`` is not among the PyPI wheels, so ``TFMessage`` is written here.
"""

from __future__ import annotations

import functools
import importlib.util
import json
import os
import re
import sys
from pathlib import Path

TF_MESSAGE = "tf2_msgs/msg/TFMessage"
# tf2_msgs/msg/TFMessage.msg of ROS 2 Jazzy (ros2/geometry2), and its type hash as
# `ros2 topic info -v /tf` shows it (recomputed from TransformStamped in the tests).
_EMBEDDED = {
    TF_MESSAGE: ("geometry_msgs/TransformStamped[] transforms\n",
                 "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087"),
}

DELIMITER = "=" * 80 + "\n"
_PACKAGE_TYPE = re.compile(r"^([a-zA-Z0-9_]+)/(?:msg/|srv/)?([a-zA-Z0-9_]+)$")
# rosbag2's own patterns: a field's type is the first word of a line.
_FIELD_TYPE = re.compile(r"(?:^|\n)\s*([a-zA-Z0-9_/]+)(?:\[[^\]]*\])?\s+")
_PRIMITIVES = frozenset({"bool", "byte", "char", "float32", "float64", "int8", "uint8",
                         "int16", "uint16", "int32", "uint32", "int64", "uint64", "string"})
_MAX_DEPTH = 50


class DefinitionNotFound(LookupError):
    """No installed package holds this type's ``.msg`` file."""


def type_name(message_type: type) -> str:
    """``pkg/msg/Type`` of an rclpy message class (e.g. ``geometry_msgs/msg/Twist``)."""
    package, kind = [*message_type.__module__.split("."), "msg"][:2]  # never raises
    return f"{package}/{kind}/{message_type.__name__}"


def _split(name: str) -> tuple[str, str]:
    match = _PACKAGE_TYPE.match(name)
    if match is None:
        raise DefinitionNotFound(name)
    return match.group(1), match.group(2)


def _prefixes(package: str) -> list[Path]:
    """Install prefixes that may hold ``share/<package>``: a sourced ROS install's
    ``AMENT_PREFIX_PATH``, this interpreter's prefix (the PyPI wheels), and the prefix of
    the package's Python module."""
    found = [Path(p) for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    found.append(Path(sys.prefix))
    spec = importlib.util.find_spec(package) if package.isidentifier() else None
    if spec is not None and spec.origin:
        found.extend(Path(spec.origin).parents)
    return found


@functools.cache
def _file(name: str, suffix: str) -> Path:
    package, short = _split(name)
    for prefix in _prefixes(package):
        path = prefix / "share" / package / "msg" / f"{short}{suffix}"
        if path.is_file():
            return path
    raise DefinitionNotFound(name)


def _text(name: str) -> str:
    package, short = _split(name)
    embedded = _EMBEDDED.get(f"{package}/msg/{short}")
    if embedded is not None:
        return embedded[0]
    return _file(name, ".msg").read_text(encoding="utf-8")


def _dependencies(text: str, package: str) -> list[str]:
    """The non-primitive field types of a ``.msg`` text, sorted as rosbag2's std::set is."""
    found = set()
    for match in _FIELD_TYPE.finditer(text):
        field = match.group(1)
        if field not in _PRIMITIVES:
            found.add(field if "/" in field else f"{package}/{field}")
    return sorted(found)


@functools.cache
def full_text(name: str) -> str:
    """The definition of ``name`` followed by each type it uses, once, as rosbag2 writes a
    ``ros2msg`` schema; :class:`DefinitionNotFound` if one of them is not installed."""
    seen: set[str] = set()

    def append(current: str, depth: int) -> str:
        if depth <= 0:
            raise DefinitionNotFound(f"{name}: dependencies nest too deep")
        text = _text(current)
        result = text
        for dependency in _dependencies(text, _split(current)[0]):
            if dependency not in seen:
                seen.add(dependency)
                result += "\n" + DELIMITER + f"MSG: {dependency}\n"
                result += append(dependency, depth - 1)
        return result

    return append(name, _MAX_DEPTH)


@functools.cache
def type_hash(name: str) -> str:
    """The type's ``RIHS01_`` hash, or "" when the installed package does not say it."""
    package, short = _split(name)
    embedded = _EMBEDDED.get(f"{package}/msg/{short}")
    if embedded is not None:
        return embedded[1]
    try:
        description = json.loads(_file(name, ".json").read_text(encoding="utf-8"))
    except (DefinitionNotFound, OSError, ValueError):
        return ""
    full = f"{package}/msg/{short}"
    for entry in description.get("type_hashes", []):
        if entry.get("type_name") == full:
            return str(entry.get("hash_string", ""))
    return ""
