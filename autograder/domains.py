"""ROS domain ids for concurrent grading runs, coordinated through lock files.

Every grading run holds an exclusive ``flock`` on ``domain-<id>.lock`` for as long as it
runs, so two runs on one machine (``grade-batch --jobs N``, two CI jobs) never share a
graph.  The kernel drops a lock when its holder dies, so a crashed run frees its domain.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path

# Domains 0-9 are left to people running nodes by hand; with Linux's default ephemeral
# port range, ids up to 101 are safe for Fast DDS.
FIRST_DOMAIN, LAST_DOMAIN = 10, 101


def lock_dir() -> Path:
    path = Path(os.environ.get("AUTOGRADER_LOCK_DIR", Path(tempfile.gettempdir())
                               / "autograder-domains"))
    path.mkdir(parents=True, exist_ok=True)
    return path


@contextlib.contextmanager
def reserve_domain(preferred: int | None = None) -> Iterator[int]:
    """Hold a free ROS domain id for the duration of the ``with`` block."""
    candidates = [preferred] if preferred is not None else range(FIRST_DOMAIN, LAST_DOMAIN + 1)
    for domain in candidates:
        fd = os.open(lock_dir() / f"domain-{domain}.lock", os.O_CREAT | os.O_RDWR, 0o666)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            continue
        try:
            yield domain
        finally:
            fcntl.flock(fd, fcntl.LOCK_UN)
            os.close(fd)
        return
    raise RuntimeError(f"no free ROS domain id in {list(candidates)}")
