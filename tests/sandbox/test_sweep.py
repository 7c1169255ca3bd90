"""The sweep: everything of a student's own user ends with its programs (processes outside
any group or cgroup, SysV IPC objects, files at the top of the shared scratch folders), and
only a student's own user is ever swept."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from autograder.sandbox.contained.launcher import user_tasks
from autograder.sandbox.isolation import student_uid
from autograder.sandbox.sweep import (
    STUDENT_UID_BASE,
    is_student_uid,
    kill_user,
    remove_leftovers,
    sweep_user,
    user_files,
    user_ipc,
    user_processes,
)

root_only = pytest.mark.skipif(os.geteuid() != 0 or shutil.which("setpriv") is None,
                               reason="needs root and setpriv to act as a student's user")


def test_only_students_own_users_are_swept():
    assert is_student_uid(student_uid(10)) and is_student_uid(student_uid(101))
    for uid in (0, os.getuid(), 1000, 65534, student_uid(0) - 1):
        assert not is_student_uid(uid)
        with pytest.raises(ValueError):
            kill_user(uid)


@root_only
def test_the_sweep_ends_a_users_processes_its_ipc_and_its_scratch_files(tmp_path):
    """A daemon in a session of its own, a SysV segment and a file in /dev/shm, all of a
    student's user and outside any process group or cgroup the grader knows: swept."""
    uid = student_uid(230)  # a domain no grading reserves
    code = ("import ctypes, os, time\n"
            "libc = ctypes.CDLL(None)\n"
            "print(libc.shmget(0x5A1A0000 + os.getpid() % 0x10000, 4096, 0o1666), flush=True)\n"
            f"open('/dev/shm/autograder-sweep-test-{uid}', 'w').write('x')\n"
            "if os.fork() == 0:\n"
            "    os.setsid()\n"
            "    time.sleep(600)\n"
            "os._exit(0)\n")
    subprocess.run(["setpriv", f"--reuid={uid}", f"--regid={uid}", "--clear-groups",
                    sys.executable, "-I", "-c", code], check=True, cwd="/", timeout=60)
    assert user_processes(uid), "the daemon runs"
    assert user_ipc(uid), "the segment exists"
    assert sweep_user(uid)
    assert user_processes(uid) == []
    assert user_ipc(uid) == []
    assert not Path(f"/dev/shm/autograder-sweep-test-{uid}").exists()


@pytest.mark.slow  # the machine's init reaps in its own time: 1.5 s here
@root_only
def test_the_sweep_ends_once_the_users_zombies_are_reaped_too():
    """A program that forked 60 children that ended at once and were never reaped: killed,
    its children are orphans the machine's init reaps in its own time, each counted against
    the user's RLIMIT_NPROC meanwhile. The sweep returns once none is counted (but the
    program itself, the caller's child and the caller's to reap)."""
    uid = student_uid(229)  # a domain no grading reserves
    code = ("import os, time\n"
            "for _ in range(60):\n"
            "    if os.fork() == 0:\n"
            "        os._exit(0)\n"
            "print('forked', flush=True)\n"
            "time.sleep(600)\n")
    program = subprocess.Popen(["setpriv", f"--reuid={uid}", f"--regid={uid}",
                                "--clear-groups", sys.executable, "-I", "-c", code],
                               cwd="/", stdout=subprocess.PIPE, text=True)
    try:
        assert program.stdout is not None and program.stdout.readline() == "forked\n"
        assert user_tasks(uid) == 61
        assert sweep_user(uid)
        assert user_processes(uid) == []
        assert user_tasks(uid) == 1  # the program's zombie, ours to reap
    finally:
        program.kill()
        program.wait()
    assert user_tasks(uid) == 0


def _status(proc: Path, pid: int, uid: int, state: str) -> None:
    (proc / str(pid)).mkdir()
    (proc / str(pid) / "status").write_text(
        f"Name:\tpython3\nState:\t{state}\nUid:\t{uid}\t{uid}\t{uid}\t{uid}\nThreads:\t2\n")


def test_a_users_live_processes_not_its_zombies_nor_others(tmp_path):
    uid = STUDENT_UID_BASE + 5
    _status(tmp_path, 10, uid, "S (sleeping)")
    _status(tmp_path, 11, uid, "Z (zombie)")
    _status(tmp_path, 12, uid + 1, "R (running)")
    _status(tmp_path, 13, uid, "D (disk sleep)")
    assert sorted(user_processes(uid, str(tmp_path))) == [10, 13]
    assert user_processes(uid + 2, str(tmp_path)) == []
    assert os.getpid() in user_processes(os.getuid())


def test_a_users_sysv_objects_by_owner_or_creator(tmp_path):
    uid = STUDENT_UID_BASE + 7
    (tmp_path / "sysvipc").mkdir()
    (tmp_path / "sysvipc" / "shm").write_text(
        "       key      shmid perms       size  cpid  lpid nattch   uid   gid  cuid  cgid\n"
        f"         1         11   666       4096     1     1      0 {uid} {uid}     0     0\n"
        f"         2         12   666       4096     1     1      0     0     0 {uid} {uid}\n"
        "         3         13   666       4096     1     1      0     0     0     0     0\n")
    (tmp_path / "sysvipc" / "sem").write_text(
        "       key      semid perms      nsems   uid   gid  cuid  cgid\n"
        f"         5         51   600          1 {uid} {uid} {uid} {uid}\n"
        "   garbled\n")
    # no "msg" file: that kind is passed over
    assert user_ipc(uid, str(tmp_path)) == [("shm", 11), ("shm", 12), ("sem", 51)]
    assert user_ipc(uid + 1, str(tmp_path)) == []


def test_a_users_files_at_the_top_of_each_scratch_folder(tmp_path):
    mine, other = tmp_path / "scratch", tmp_path / "other"
    mine.mkdir()
    other.mkdir()
    (mine / "file").write_text("x")
    (mine / "folder").mkdir()
    (mine / "folder" / "inner").write_text("x")  # under its folder: the folder is listed
    (mine / "link").symlink_to("/etc/passwd")  # the link's own owner, not its target's
    uid = os.getuid()
    found = user_files(uid, (str(mine), str(tmp_path / "missing"), str(other)))
    assert sorted(found) == [str(mine / "file"), str(mine / "folder"), str(mine / "link")]
    assert user_files(uid + 1, (str(mine),)) == []


@root_only
def test_leftovers_are_removed_as_their_user_links_not_followed():
    """What the student's user owns at the top of a scratch folder goes, a closed folder with
    all in it; a link goes, what it points to stays; what another user owns stays."""
    uid = student_uid(231)  # a domain no grading reserves
    top = Path(tempfile.mkdtemp(dir="/tmp"))  # reachable by the student's user
    os.chmod(top, 0o755)
    scratch = top / "scratch"
    scratch.mkdir()
    os.chmod(scratch, 0o1777)
    try:
        target = top / "kept"
        target.write_text("the grader's\n")
        code = ("import os, sys\n"
                "s = sys.argv[1]\n"
                "os.makedirs(s + '/closed/deep')\n"
                "open(s + '/closed/deep/f', 'w').write('x')\n"
                "os.chmod(s + '/closed/deep', 0)\n"
                "os.chmod(s + '/closed', 0)\n"
                "open(s + '/file', 'w').write('x')\n"
                "os.symlink(sys.argv[2], s + '/link')\n")
        subprocess.run(["setpriv", f"--reuid={uid}", f"--regid={uid}", "--clear-groups",
                        sys.executable, "-I", "-c", code, str(scratch), str(target)],
                       check=True, cwd="/", timeout=60)
        (scratch / "graders").write_text("mine\n")
        assert len(user_files(uid, (str(scratch),))) == 3
        remove_leftovers(uid, (str(scratch),))
        assert sorted(p.name for p in scratch.iterdir()) == ["graders"]
        assert target.read_text() == "the grader's\n"
    finally:
        shutil.rmtree(top, ignore_errors=True)
