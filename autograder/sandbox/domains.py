"""ROS domain ids for concurrent grading runs, coordinated through lock files.

Every grading run holds an exclusive ``flock`` on ``domain-<id>.lock`` for as long as it
runs, so two runs on one machine (``grade-batch --jobs N``, two CI jobs, two students on
a lab PC) never share a graph.  The kernel drops a lock when its last holder dies, so a
crashed run frees its domain; the run's pytest child inherits the lock's descriptor and
holds the domain as long as it lives, even past its parent.

The lock folder (``AUTOGRADER_LOCK_DIR``, default ``/tmp/autograder-domains``) is shared
by every user of the machine: made sticky and world-writable like ``/tmp`` itself, with
lock files anyone may lock (``flock`` needs only a descriptor opened for reading, so a
file another user created, whatever their umask, still works).  Where the shared folder
cannot be used (made by an older version, or a read-only ``/tmp``), each user falls back
to a folder of their own; other users' runs are then avoided by looking at the wire: a
domain whose Fast DDS ports have a socket bound on this machine is taken.

A student's program that runs as a user of its own (strict isolation, isolation by user)
can open the shared lock files too, and bind sockets on any domain's ports. Neither may
leave the machine without a domain, so root's runs coordinate through a folder only root
can enter, and every run passes over a shared lock or a socket whose holder is a student's
user: only graders and people's own nodes count as someone on a domain.
"""

from __future__ import annotations

import contextlib
import dataclasses
import fcntl
import functools
import os
import stat
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path

from autograder.core.errors import GraderError
from autograder.sandbox.sweep import is_student_uid

# Domains 0-9 are left to people running nodes by hand; with Linux's default ephemeral
# port range, ids up to 101 are safe for Fast DDS.
FIRST_DOMAIN, LAST_DOMAIN = 10, 101
# Fast DDS (RTPS) ports: domain d uses PORT_BASE + DOMAIN_GAIN * d and the 250 above it.
PORT_BASE, DOMAIN_GAIN = 7400, 250


class NoDomain(GraderError):
    """No ROS domain could be reserved for a grading run."""


@dataclasses.dataclass(frozen=True)
class DomainLock:
    """A reserved domain and the open lock files that hold it (inheritable by a child)."""

    domain: int
    fds: tuple[int, ...]


# The shared lock folder unless AUTOGRADER_LOCK_DIR says otherwise: a fixed path, not under
# $TMPDIR, which differs between users and jobs (pam_tmpdir, CI runners, a test's own). Two
# graders with different folders would take the same domain, and in strict isolation no
# bound port shows the other (each run has its network namespace): one's sweep of the
# domain's student user would then kill the other's student.
DEFAULT_LOCK_DIR = Path("/tmp/autograder-domains")


def shared_lock_dir() -> Path:
    return Path(os.environ.get("AUTOGRADER_LOCK_DIR", DEFAULT_LOCK_DIR))


def _usable_shared(folder: Path) -> bool:
    """Make ``folder`` a sticky world-writable folder if we may; True if we can lock in it."""
    try:
        folder.mkdir(mode=0o1777, parents=True, exist_ok=True)
    except OSError:
        return False
    try:
        info = folder.stat()
        if info.st_uid == os.geteuid() and stat.S_IMODE(info.st_mode) != 0o1777:
            os.chmod(folder, 0o1777)  # mkdir's mode went through the umask
    except OSError:
        pass
    return os.access(folder, os.W_OK | os.X_OK)


def lock_dirs() -> tuple[Path, Path | None]:
    """Where runs lock their domains: the shared folder, or where this user cannot use it
    (and always for root, whose students could lock the shared one), a folder of this
    user's own; with the shared one's existing locks, as far as they can be opened."""
    shared = shared_lock_dir()
    uid = os.geteuid()
    usable = _usable_shared(shared)
    if usable and uid != 0:
        return shared, None
    return own_lock_dir(), (shared if usable or shared.is_dir() else None)


def own_lock_dir() -> Path:
    """A lock folder only this user may enter."""
    shared, uid = shared_lock_dir(), os.geteuid()
    for own in (shared.with_name(f"{shared.name}-{uid}"),
                Path(tempfile.gettempdir()) / f"autograder-domains-{uid}",
                Path.home() / ".cache" / "autograder-domains"):
        try:
            own.mkdir(mode=0o700, parents=True, exist_ok=True)
        except OSError:
            continue
        if own.stat().st_uid == uid and os.access(own, os.W_OK):
            return own
    raise NoDomain(f"no folder for domain locks: {shared} cannot be used by this user "
                   f"(set AUTOGRADER_LOCK_DIR to a folder every grading user may write)")


def _open_lock(path: Path) -> int | None:
    """A descriptor on ``path`` to flock, creating it readable and writable by all; None
    where it cannot be had. Never O_CREAT on another user's file: in a sticky folder the
    kernel refuses that (``fs.protected_regular``)."""
    for _attempt in range(3):
        try:
            return os.open(path, os.O_RDONLY | os.O_CLOEXEC)
        except FileNotFoundError:
            pass
        except OSError:
            return None
        try:
            fd = os.open(path, os.O_RDONLY | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o666)
        except FileExistsError:
            continue  # another run made it just now: open theirs
        except OSError:
            return None
        with contextlib.suppress(OSError):
            os.fchmod(fd, 0o666)  # whatever the umask: any user may open it
        return fd
    return None


def udp_sockets(tables: Iterable[str] = ("/proc/net/udp", "/proc/net/udp6"),
                ) -> list[tuple[int, int]]:
    """Every UDP socket bound on this machine (this network namespace): (local port, the
    user who made it, as the kernel keeps it)."""
    found = []
    for table in tables:
        try:
            lines = Path(table).read_text().splitlines()[1:]
        except OSError:
            continue
        for line in lines:
            fields = line.split()
            if len(fields) > 7:
                found.append((int(fields[1].rsplit(":", 1)[1], 16), int(fields[7])))
    return found


def busy_on_the_wire(domain: int, tables: Iterable[str] = ("/proc/net/udp",
                                                            "/proc/net/udp6")) -> bool:
    """True if a UDP socket on this machine (this network namespace) is bound to one of
    the domain's Fast DDS ports by anyone but a student's user: someone is on that
    domain, locks or not. (A student's own grading holds its domain by its grader's lock;
    its sockets elsewhere are no one's reservation.)"""
    low = PORT_BASE + DOMAIN_GAIN * domain
    return any(low <= port < low + DOMAIN_GAIN and not is_student_uid(uid)
               for port, uid in udp_sockets(tables))


def lock_holders(path: Path, locks: str = "/proc/locks",
                 proc: str = "/proc") -> list[int | None]:
    """The users of the processes holding a ``flock`` on ``path``, as the kernel lists
    them: None where the process that took it has ended (a child holds it) or cannot be
    read."""
    try:
        info = path.stat()
        table = Path(locks).read_text().splitlines()
    except OSError:
        return []
    device = f"{os.major(info.st_dev):02x}:{os.minor(info.st_dev):02x}:{info.st_ino}"
    holders: list[int | None] = []
    for line in table:
        fields = line.split()
        if len(fields) < 6 or fields[1] != "FLOCK" or fields[5] != device:
            continue
        try:
            status = Path(proc, fields[4], "status").read_text()
            holders.append(int(status.split("\nUid:", 1)[1].split()[0]))
        except (OSError, IndexError, ValueError):
            holders.append(None)
    return holders


def held_by_students_only(path: Path, domain: int) -> bool:
    """True if the only holders of ``path``'s lock are students' programs (a lock another
    user's run holds is never passed over; where its holder is unknown, the domain's
    ports tell)."""
    holders = lock_holders(path)
    if any(uid is not None and not is_student_uid(uid) for uid in holders):
        return False
    return None not in holders or not busy_on_the_wire(domain)


@functools.cache
def ephemeral_low(path: str = "/proc/sys/net/ipv4/ip_local_port_range") -> int:
    """The first port the kernel hands out to sockets bound to none (Linux: 32768)."""
    try:
        return int(Path(path).read_text().split()[0])
    except (OSError, ValueError, IndexError):
        return 32768


def domain_of_port(port: int) -> int | None:
    """The ROS domain whose Fast DDS ports hold ``port``; None outside them, and None for
    a port the kernel may have handed out to any socket (Fast DDS's own sending sockets
    among them), where a domain's ports cannot be told apart: gradings' domains
    (``FIRST_DOMAIN`` to ``LAST_DOMAIN``) lie below."""
    if port < PORT_BASE or port >= ephemeral_low():
        return None
    domain = (port - PORT_BASE) // DOMAIN_GAIN
    return domain if domain <= 232 else None


def bound_on_domains(tables: Iterable[str] = ("/proc/net/udp", "/proc/net/udp6"),
                     ) -> list[tuple[int, int]]:
    """Every UDP socket bound on this machine (this network namespace) to a port of a ROS
    domain: (domain, the socket's user). The kernel keeps the user who made each socket,
    so who is on a domain can be told without reading another user's processes."""
    return [(domain, uid) for port, uid in udp_sockets(tables)
            if (domain := domain_of_port(port)) is not None]


TAKEN = -1  # another run holds the lock
UNAVAILABLE = -2  # the lock file cannot be had (a folder we may not write)


def _lock(folder: Path, domain: int) -> int:
    """A descriptor holding ``domain``'s lock in ``folder``, or TAKEN, or UNAVAILABLE."""
    fd = _open_lock(folder / f"domain-{domain}.lock")
    if fd is None:
        return UNAVAILABLE
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(fd)
        return TAKEN
    return fd


def _take(domain: int, own: Path, shared: Path | None) -> DomainLock | None:
    """Lock ``domain`` in our folder (and in the shared one, where its file can still be
    opened); None if anyone holds it or a program uses its ports."""
    held = [_lock(own, domain)]
    if shared is not None:
        held.append(_lock(shared, domain))
    # A lock only students' programs hold is no one's reservation. Where it is the one
    # this user's runs coordinate through, a lock in a folder of the user's own stands in.
    for i, folder in enumerate((own, shared)):
        if folder is not None and held[i] == TAKEN \
                and held_by_students_only(folder / f"domain-{domain}.lock", domain):
            held[i] = _lock(own_lock_dir(), domain) if i == 0 else UNAVAILABLE
    fds = tuple(fd for fd in held if fd >= 0)
    if held[0] < 0 or TAKEN in held or busy_on_the_wire(domain):
        for fd in fds:
            os.close(fd)
        return None
    return DomainLock(domain, fds)


@contextlib.contextmanager
def hold_domain(preferred: int | None = None) -> Iterator[DomainLock]:
    """Hold a free ROS domain for the ``with`` block; :class:`NoDomain` if none is free."""
    candidates = [preferred] if preferred is not None else range(FIRST_DOMAIN, LAST_DOMAIN + 1)
    own, shared = lock_dirs()
    for domain in candidates:
        lock = _take(domain, own, shared)
        if lock is None:
            continue
        try:
            yield lock
        finally:
            for fd in lock.fds:
                os.close(fd)  # the lock drops when the last holder (a child too) closes
        return
    raise NoDomain(f"no free ROS domain id among {candidates[0]}-{candidates[-1]} "
                   f"(lock folder {own}): each is locked by another run or its ports are "
                   f"in use on this machine")


@contextlib.contextmanager
def reserve_domain(preferred: int | None = None) -> Iterator[int]:
    """Hold a free ROS domain id for the duration of the ``with`` block."""
    with hold_domain(preferred) as lock:
        yield lock.domain
