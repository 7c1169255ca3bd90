"""The launcher between the grader and a student's program.

Runs as a fresh single-threaded process (so no ``preexec_fn`` runs in the threaded
grader) and ``exec``s the student's command once it is contained::

    python -m autograder.sandbox.contained.launcher SPEC_JSON -- COMMAND...

SPEC holds ``limits`` (see ``autograder.core.exercise.Limits``), ``cgroups`` (folders to
join), ``workdir`` (where the program runs) and ``status_fd``, and for strict isolation
``uid``, ``hide`` (paths to cover with an empty read-only filesystem) and ``workdir_mb``
(``workdir`` becomes a tmpfs of that size, owned by ``uid``, filled with the files staged
there).  Strict steps need root; the mounts happen in mount and IPC namespaces of the
student's own, with a ``/proc`` showing only the student's processes, so the grader
keeps its view.  Every program runs with no new privileges.

The launcher is started isolated, from ``/`` (:mod:`autograder.sandbox.privileged`): it
runs as root until the program is contained, so nothing of the student's may be on its
module path.

``status_fd`` is the write end of a pipe, close-on-exec, as :mod:`subprocess` does it: if
anything fails before the student's program is exec'd (a mount, a cgroup, setuid, a
missing interpreter), the launcher writes what failed there and exits; if the exec
succeeds the pipe closes with nothing written.  The grader can thus never take a failure
of ours for the student's program exiting.
"""

from __future__ import annotations

import ctypes
import errno
import json
import os
import resource
import sys
from collections.abc import Iterator
from pathlib import Path

_RLIMITS = {
    "cpu_seconds": (resource.RLIMIT_CPU, 1),
    "memory_mb": (resource.RLIMIT_AS, 1024 * 1024),
    "processes": (resource.RLIMIT_NPROC, 1),
    "open_files": (resource.RLIMIT_NOFILE, 1),
    "file_size_mb": (resource.RLIMIT_FSIZE, 1024 * 1024),
}
CLONE_NEWNS, CLONE_NEWIPC = 0x00020000, 0x08000000
PR_SET_NO_NEW_PRIVS = 38
MS_RDONLY, MS_NOSUID, MS_NODEV, MS_NOEXEC = 1, 2, 4, 8
MS_REMOUNT, MS_BIND, MS_REC, MS_PRIVATE = 32, 4096, 0x4000, 1 << 18
# Exit status of a launcher that failed before the exec (what failed is on the status pipe).
LAUNCH_FAILED = 121


def apply_limits(limits: dict[str, int]) -> None:
    for key, (which, scale) in _RLIMITS.items():
        if key not in limits:
            continue
        value = int(limits[key]) * scale
        if which == resource.RLIMIT_NPROC and "uid" not in limits:
            if os.geteuid() == 0:
                continue  # root is exempt from RLIMIT_NPROC; the pids cgroup counts instead
            # Without a uid of its own the student shares the grader's user, and
            # RLIMIT_NPROC counts every thread that user runs: the grader's children and
            # their other students too (four module children at once left a reference
            # solution unable to start a thread). Allow ``processes`` beyond those.
            value += user_tasks(os.getuid())
            hard = resource.getrlimit(which)[1]
            if hard != resource.RLIM_INFINITY:
                value = min(value, hard)
        resource.setrlimit(which, (value, value))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))


def process_statuses(proc: str = "/proc") -> Iterator[tuple[int, int, bytes, int]]:
    """Every process now: (pid, real user, state letter, threads), from its ``status``;
    one gone meanwhile, or a kernel thread's short status, is passed over."""
    for name in os.listdir(proc):
        if not name.isdigit():
            continue
        try:
            with open(f"{proc}/{name}/status", "rb") as fh:
                fields = dict(line.split(b":", 1) for line in fh if b":" in line)
            yield (int(name), int(fields[b"Uid"].split()[0]), fields.get(b"State", b"").strip()[:1],
                   int(fields[b"Threads"]))
        except (OSError, KeyError, ValueError, IndexError):
            continue


def user_tasks(uid: int, proc: str = "/proc") -> int:
    """Processes and threads whose real user is ``uid`` now: what RLIMIT_NPROC counts."""
    return sum(threads for _pid, owner, _state, threads in process_statuses(proc)
               if owner == uid)


def _libc() -> ctypes.CDLL:
    return ctypes.CDLL(None, use_errno=True)


def _check(result: int, what: str) -> None:
    if result != 0:
        errno = ctypes.get_errno()
        raise OSError(errno, f"{what}: {os.strerror(errno)}")


def _mount(source: str, target: str, fstype: str | None, flags: int, data: str | None) -> None:
    libc = _libc()
    _check(libc.mount(source.encode(), target.encode(), fstype.encode() if fstype else None,
                      ctypes.c_ulong(flags), data.encode() if data else None),
           f"mount {target}")


def private_mounts() -> None:
    """A mount namespace of our own, whose changes never reach the grader's, and an IPC
    namespace: SysV shared memory, queues and semaphores and POSIX message queues the
    program makes are its own, and the kernel destroys them with its last process."""
    _check(_libc().unshare(CLONE_NEWNS | CLONE_NEWIPC), "unshare")
    _mount("none", "/", None, MS_REC | MS_PRIVATE, None)


def private_proc() -> bool:
    """A ``/proc`` of the program's own in which only its user's processes appear
    (``hidepid=invisible``): not the grader's, not other runs' command lines. Each such
    mount has its options to itself since Linux 5.8; an older kernel refuses the option
    (EINVAL), and then ``/proc`` stays as it is (False): an older kernel would apply it to
    the machine's own ``/proc``."""
    try:
        _mount("proc", "/proc", "proc", MS_NOSUID | MS_NODEV | MS_NOEXEC, "hidepid=invisible")
    except OSError as exc:
        if exc.errno == errno.EINVAL:
            return False
        raise
    return True


def no_new_privileges() -> None:
    """No exec of the program or of anything it starts gains privileges (set-user-ID
    programs, file capabilities): ``PR_SET_NO_NEW_PRIVS``."""
    _check(_libc().prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0), "prctl(PR_SET_NO_NEW_PRIVS)")


# What a student's program may see of the machine: the system, and what it runs on.
SYSTEM = ("/usr", "/bin", "/sbin", "/lib", "/lib32", "/lib64", "/libx32", "/etc", "/proc",
          "/sys", "/dev", "/tmp")


def _cover(path: str) -> None:
    """Cover ``path`` with an empty, read-only filesystem nobody but root can enter."""
    _mount("tmpfs", path, "tmpfs", MS_RDONLY | MS_NOSUID | MS_NODEV | MS_NOEXEC,
           "size=4k,mode=000")


def hide(paths: list[str]) -> None:
    for path in paths:
        if os.path.isdir(path):
            _cover(path)


def hide_all_but(needed: list[str]) -> None:
    """Cover every folder that is neither system nor on the way to a ``needed`` path, so no
    copy of a course anywhere on the machine (a checkout, a clone in /tmp) is in reach."""
    needed = [os.path.realpath(p) for p in needed]

    def walk(folder: str) -> None:
        try:
            entries = sorted(os.scandir(folder), key=lambda e: e.name)
        except OSError:
            return
        for entry in entries:
            path = entry.path
            if not entry.is_dir(follow_symlinks=False) or path in SYSTEM:
                continue
            if any(n == path for n in needed):
                continue  # needed whole
            if any(n.startswith(path + os.sep) for n in needed):
                walk(path)  # on the way to something needed: look inside
            else:
                try:
                    _cover(path)
                except OSError:
                    pass  # a special mount we may not cover; permissions still apply

    walk("/")


def barrier_above(path: str) -> str | None:
    """The topmost folder above ``path`` that the student would not get through: ``/tmp``
    and ``/dev/shm`` (replaced by fresh ones), or one closed to other users (``/root``)."""
    parts = Path(path).parts
    for depth in range(2, len(parts) + 1):
        folder = str(Path(*parts[:depth]))
        if folder in FRESH or not os.stat(folder).st_mode & 0o001:
            return folder
    return None


def _bind_read_only(fd: int, target: str) -> None:
    os.makedirs(target, mode=0o755, exist_ok=True)
    _mount(f"/proc/self/fd/{fd}", target, None, MS_BIND | MS_REC, None)
    _mount("none", target, None, MS_REMOUNT | MS_BIND | MS_RDONLY | MS_NOSUID | MS_NODEV,
           None)


# Shared scratch folders the student gets fresh and empty: other runs' files, stray
# copies of a course (a clone in /tmp) are not in reach.
FRESH = ("/tmp", "/dev/shm")


def fill_workdir(workdir: str, size_mb: int, uid: int, needed: list[str]) -> None:
    """Give the student fresh, empty ``/tmp`` and ``/dev/shm``, and in it ``workdir``: a
    tmpfs of ``size_mb`` owned by ``uid``, holding the files staged there.

    What the program runs on (``needed``: the interpreter, the venv) stays reachable,
    read-only, also where it lies under ``/tmp`` or under a folder closed to other users:
    that folder is replaced by an empty one holding only what is needed, bound in."""
    staged = {p.name: p.read_bytes() for p in Path(workdir).iterdir() if p.is_file()}
    barriers: dict[str, list[str]] = {folder: [] for folder in FRESH if os.path.isdir(folder)}
    for path in dict.fromkeys(os.path.realpath(p) for p in needed):
        barrier = barrier_above(path)
        if barrier is not None:
            barriers.setdefault(barrier, []).append(path)
    # Reach each needed folder before anything covers it; bind it back afterwards.
    paths = sorted(p for group in barriers.values() for p in group)
    outermost = [p for p in paths if not any(p.startswith(q + os.sep) for q in paths)]
    held = {path: os.open(path, os.O_PATH | os.O_DIRECTORY) for path in outermost}
    os.umask(0o022)
    for barrier in sorted(barriers, key=len):
        mode = "1777" if barrier in FRESH else "0755"
        _mount("tmpfs", barrier, "tmpfs", MS_NOSUID | MS_NODEV, f"size=1m,mode={mode}")
    for path, fd in held.items():
        _bind_read_only(fd, path)
        os.close(fd)
    os.makedirs(workdir, exist_ok=True)
    _mount("tmpfs", workdir, "tmpfs", MS_NOSUID | MS_NODEV,
           f"size={size_mb}m,mode=0700,uid={uid},gid={uid}")
    for name, data in staged.items():
        target = Path(workdir) / name
        target.write_bytes(data)
        os.chown(target, uid, uid)
    log = Path(workdir) / ".ros" / "log"
    log.mkdir(parents=True)
    for folder in (log.parent, log):
        os.chown(folder, uid, uid)


def give_folder(workdir: str, uid: int) -> None:
    """Isolation by user: the student's folder and what was staged in it become its user's,
    closed to everyone else (0700)."""
    for root, dirs, files in os.walk(workdir):
        for name in (*dirs, *files):
            os.lchown(os.path.join(root, name), uid, uid)
    os.chown(workdir, uid, uid)
    os.chmod(workdir, 0o700)


def become(uid: int) -> None:
    os.setgroups([])
    os.setgid(uid)
    os.setuid(uid)


def interpreter_paths() -> list[str]:
    """What the student's Python needs to run here: the interpreter, its environment, and
    every folder on its module path (a venv's site-packages, a system ROS install's), but
    not this platform's own checkout, whose way onto the path is the launcher's."""
    own = os.path.realpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                        ".."))
    here = os.path.realpath(os.getcwd())
    found = [sys.prefix, sys.base_prefix, sys.exec_prefix,
             os.path.dirname(os.path.realpath(sys.executable))]
    found += [p for p in sys.path if os.path.isabs(p) and os.path.isdir(p)
              and os.path.realpath(p) not in (own, here)]
    found += [p for p in os.environ.get("LD_LIBRARY_PATH", "").split(os.pathsep)
              if os.path.isabs(p) and os.path.isdir(p)]
    return found


def contain(spec: dict, stage: list[str]) -> None:
    """Every step between the grader and the student's program, naming each in ``stage``."""
    uid = spec.get("uid")
    if uid is not None and not spec.get("namespaces", True):
        stage[0] = "the student's folder"
        give_folder(spec["workdir"], uid)
    elif uid is not None:
        stage[0] = "mount namespace"
        private_mounts()
        stage[0] = "hiding the course"
        hide(spec.get("hide", []))
        hide_all_but([*interpreter_paths(), spec["workdir"]])
        stage[0] = "working directory"
        fill_workdir(spec["workdir"], int(spec.get("workdir_mb", 64)), uid,
                     interpreter_paths())
        stage[0] = "a /proc of its own"
        private_proc()
    stage[0] = "cgroup"
    for cgroup in spec.get("cgroups", []):
        with open(os.path.join(cgroup, "cgroup.procs"), "w") as fh:
            fh.write(str(os.getpid()))
    stage[0] = "resource limits"
    limits = dict(spec.get("limits", {}))
    if uid is not None:
        limits["uid"] = uid
    apply_limits(limits)
    stage[0] = "no new privileges"
    no_new_privileges()
    if uid is not None:
        stage[0] = "switching to the student's user"
        become(uid)
    stage[0] = "working directory"
    os.chdir(spec["workdir"])  # only now: the launcher itself started from "/"


def main(argv: list[str]) -> None:
    split = argv.index("--")
    spec = json.loads(argv[0])
    status_fd = spec.get("status_fd")
    if status_fd is not None:
        os.set_inheritable(status_fd, False)  # closed by a successful exec, not before
    stage = ["start"]
    command = argv[split + 1:]
    try:
        contain(spec, stage)
        stage[0] = f"exec {command[0]}"
        os.execvp(command[0], command)
    except BaseException as exc:  # every failure before the exec is ours
        report = json.dumps({"stage": stage[0], "error": f"{type(exc).__name__}: {exc}"})
        if status_fd is None:
            print(report, file=sys.stderr)
        else:
            os.write(status_fd, report.encode())
        os._exit(LAUNCH_FAILED)


if __name__ == "__main__":
    main(sys.argv[1:])
