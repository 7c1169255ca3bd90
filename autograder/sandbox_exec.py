"""The launcher between the grader and a student's program.

Runs as a fresh single-threaded process (so no ``preexec_fn`` runs in the threaded
grader) and ``exec``s the student's command once it is contained::

    python -m autograder.sandbox_exec SPEC_JSON -- COMMAND...
    python -m autograder.sandbox_exec --check UID      # can UID run Python and rclpy?

SPEC holds ``limits`` (see ``autograder.exercise.Limits``) and ``cgroups`` (folders to
join), and for strict isolation ``uid``, ``hide`` (paths to cover with an empty read-only
filesystem), ``workdir`` and ``workdir_mb`` (a tmpfs of that size, owned by ``uid``,
filled with the files staged there).  Strict steps need root; the mounts happen in a
mount namespace of the student's own, so the grader keeps its view.
"""

from __future__ import annotations

import ctypes
import json
import os
import resource
import sys
from pathlib import Path

_RLIMITS = {
    "cpu_seconds": (resource.RLIMIT_CPU, 1),
    "memory_mb": (resource.RLIMIT_AS, 1024 * 1024),
    "processes": (resource.RLIMIT_NPROC, 1),
    "open_files": (resource.RLIMIT_NOFILE, 1),
    "file_size_mb": (resource.RLIMIT_FSIZE, 1024 * 1024),
}
CLONE_NEWNS = 0x00020000
MS_RDONLY, MS_NOSUID, MS_NODEV, MS_NOEXEC = 1, 2, 4, 8
MS_REC, MS_PRIVATE = 0x4000, 1 << 18


def apply_limits(limits: dict[str, int]) -> None:
    for key, (which, scale) in _RLIMITS.items():
        if key not in limits:
            continue
        value = int(limits[key]) * scale
        if which == resource.RLIMIT_NPROC and os.geteuid() == 0 and "uid" not in limits:
            continue  # root is exempt from RLIMIT_NPROC; the pids cgroup counts instead
        resource.setrlimit(which, (value, value))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))


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
    """A mount namespace of our own, whose changes never reach the grader's."""
    _check(_libc().unshare(CLONE_NEWNS), "unshare")
    _mount("none", "/", None, MS_REC | MS_PRIVATE, None)


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


def fill_workdir(workdir: str, size_mb: int, uid: int) -> None:
    """Give the student fresh, empty ``/tmp`` and ``/dev/shm`` (other runs' files, stray
    copies of a course), and in it ``workdir``: a tmpfs of ``size_mb`` owned by ``uid``,
    holding the files staged there."""
    staged = {p.name: p.read_bytes() for p in Path(workdir).iterdir() if p.is_file()}
    for shared in ("/tmp", "/dev/shm"):
        if os.path.isdir(shared):
            _mount("tmpfs", shared, "tmpfs", MS_NOSUID | MS_NODEV, "size=1m,mode=1777")
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


def become(uid: int) -> None:
    os.setgroups([])
    os.setgid(uid)
    os.setuid(uid)


def main(argv: list[str]) -> None:
    if argv[:1] == ["--check"]:
        private_mounts()
        become(int(argv[1]))
        os.chdir("/")
        os.execv(sys.executable, [sys.executable, "-c", "import rclpy"])
    split = argv.index("--")
    spec = json.loads(argv[0])
    uid = spec.get("uid")
    if uid is not None:
        private_mounts()
        hide(spec.get("hide", []))
        hide_all_but([sys.prefix, sys.base_prefix, sys.exec_prefix,
                      os.path.dirname(os.path.realpath(sys.executable)), spec["workdir"]])
        fill_workdir(spec["workdir"], int(spec.get("workdir_mb", 64)), uid)
    for cgroup in spec.get("cgroups", []):
        with open(os.path.join(cgroup, "cgroup.procs"), "w") as fh:
            fh.write(str(os.getpid()))
    limits = dict(spec.get("limits", {}))
    if uid is not None:
        limits["uid"] = uid
    apply_limits(limits)
    if uid is not None:
        become(uid)
        os.chdir(spec["workdir"])
    command = argv[split + 1:]
    os.execvp(command[0], command)


if __name__ == "__main__":
    main(sys.argv[1:])
