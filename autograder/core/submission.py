"""Find the student's file in what they submitted, and give the grader a copy to run.

What a student submits is read as untrusted input by a process that may run as root: each
file is opened with ``O_NOFOLLOW`` and ``O_NONBLOCK`` and checked with ``fstat`` on the
open descriptor (so a link cannot be swapped in between), only regular files are taken,
and each is read up to a bound. A symbolic link (to ``/etc/shadow``, a hidden test,
another student's file), a device (``/dev/zero``), a FIFO or a file over the bound is the
student's error, named plainly (:class:`SubmissionRefused`), never followed or read.
"""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path

from autograder.i18n import _

MAX_FILE_BYTES = 1_000_000
"""The largest file the grader copies: the node file or one of its sibling modules."""
MAX_MODULES = 64
"""The most sibling ``.py`` modules staged beside the node file."""


class SubmissionNotFound(Exception):
    """SUBMISSION names no file the exercise can grade."""


class SubmissionRefused(SubmissionNotFound):
    """SUBMISSION holds something the grader will not read: a link, a device, a FIFO, a
    file too large. The message names the file and says what to do."""


def locate(submission: Path, filename: str) -> Path:
    """The student's ``filename``: SUBMISSION itself, or the file of that name inside it
    (in a sub-folder if exactly one holds it). Links are never followed into folders."""
    if submission.is_dir():
        candidate = submission / filename
        if candidate.is_symlink() or candidate.exists():
            return candidate  # checked, not followed, when it is read
        matches = sorted(p for p in _walk(submission) if p.name == filename)
        if len(matches) == 1:
            return matches[0]
        raise SubmissionNotFound(_("{folder} holds no {file}").format(
            folder=submission, file=filename))
    if submission.is_symlink() or submission.exists():
        return submission
    raise SubmissionNotFound(_("{path} does not exist").format(path=submission))


def _walk(folder: Path) -> list[Path]:
    """Every entry below ``folder``, without entering linked folders."""
    found = []
    for root, dirs, files in os.walk(folder, followlinks=False):
        found += [Path(root) / name for name in (*files, *dirs)]
    return found


def read_untrusted(path: Path, limit: int = MAX_FILE_BYTES) -> bytes:
    """The bytes of the student's regular file ``path``; :class:`SubmissionRefused` for a
    link, a device, a FIFO, a folder or a file over ``limit`` bytes."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise SubmissionRefused(_(
                "{file} is a symbolic link: submit the file itself").format(
                file=path.name)) from None
        raise SubmissionRefused(_("{file} cannot be read: {error}").format(
            file=path.name, error=exc.strerror)) from None
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            if stat.S_ISDIR(mode):
                message = _("{file} is a folder, not a regular file: submit the file itself")
            elif stat.S_ISFIFO(mode):
                message = _("{file} is a FIFO, not a regular file: submit the file itself")
            elif stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
                message = _("{file} is a device, not a regular file: submit the file itself")
            else:
                message = _("{file} is a special file, not a regular file: submit the file "
                            "itself")
            raise SubmissionRefused(message.format(file=path.name))
        chunks, size = [], 0
        while chunk := os.read(fd, 65536):
            size += len(chunk)
            if size > limit:
                raise SubmissionRefused(_(
                    "{file} is larger than {limit} KB: submit your source code only").format(
                    file=path.name, limit=limit // 1000))
            chunks.append(chunk)
        return b"".join(chunks)
    finally:
        os.close(fd)


def read_submission(source: Path, filename: str) -> dict[str, bytes]:
    """The files of a submission to stage, by name: the node file ``source`` (staged as
    ``filename``) and each sibling ``.py`` module beside it, each read with
    :func:`read_untrusted`. Raises :class:`SubmissionRefused` naming the first file the
    grader will not read: the whole submission is refused, never part of it."""
    siblings = sorted(p for p in source.parent.glob("*.py") if p.name != source.name)
    if len(siblings) > MAX_MODULES:
        raise SubmissionRefused(_(
            "{folder} holds {count} Python files beside your node; the grader takes at most "
            "{limit}: submit only your node and the modules it imports").format(
            folder=source.parent, count=len(siblings), limit=MAX_MODULES))
    files = {p.name: read_untrusted(p) for p in siblings}
    files.pop(filename, None)  # the node file below wins over a sibling of its name
    files[filename] = read_untrusted(source)
    return files


def check(submission: Path, filename: str) -> Path:
    """The student's file in ``submission``, read once to refuse what the grader will not
    take (:class:`SubmissionNotFound`, :class:`SubmissionRefused`) before any grading:
    besides what :func:`read_untrusted` refuses, a file that is not a node Python runs
    (:func:`autograder.core.source.check_source`: not ``.py``, empty, not UTF-8, a syntax
    error, no node), named as the student gave it."""
    from autograder.core.source import SourceRefused, check_source

    source = locate(submission, filename)
    try:
        check_source(read_submission(source, filename), filename, str(source))
    except SourceRefused as exc:
        raise SubmissionRefused(str(exc)) from None
    return source


def stage(source: Path, filename: str, dest: Path) -> Path:
    """Copy the student's file (and its sibling ``.py`` modules) into ``dest``, a folder of
    the grader's, as regular files of its own (see :func:`read_submission`).

    The student's process runs from this copy, so nothing it does touches the original.
    """
    dest.mkdir(parents=True, exist_ok=True)
    for name, data in read_submission(source, filename).items():
        (dest / name).write_bytes(data)
    return dest / filename
