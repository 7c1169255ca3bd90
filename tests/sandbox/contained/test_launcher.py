"""The launcher: what a contained program gets (its limits, no new privileges, its folder,
in strict isolation a user, a /tmp and a /proc of its own and the course out of sight), and
the stage it names when something before the exec failed.

Each launch runs the launcher as the grader does (``module_command``, from ``/``), with a
one-line Python program in place of a student's."""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from autograder.sandbox.contained import launcher
from autograder.sandbox.contained.launcher import (
    LAUNCH_FAILED,
    apply_limits,
    interpreter_paths,
    process_statuses,
    user_tasks,
)
from autograder.sandbox.privileged import PACKAGE_PARENT, SAFE_CWD, module_command

LIMITS = {"cpu_seconds": 7, "memory_mb": 900, "processes": 77, "open_files": 99,
          "file_size_mb": 3}
# What a launched program reports of itself, as one JSON line.
SHOW_SELF = """\
import json, os, resource
status = dict(line.split(":", 1) for line in open("/proc/self/status") if ":" in line)
limits = {name: resource.getrlimit(getattr(resource, name))[0] for name in
          ("RLIMIT_CPU", "RLIMIT_AS", "RLIMIT_NPROC", "RLIMIT_NOFILE", "RLIMIT_FSIZE",
           "RLIMIT_CORE")}
print(json.dumps({"cwd": os.getcwd(), "uid": os.getuid(), "gid": os.getgid(),
                  "groups": os.getgroups(), "no_new_privs": status["NoNewPrivs"].strip(),
                  "limits": limits}))
"""


def _launch(spec: dict, command: list[str],
            timeout: float = 120) -> tuple[int, str, str, dict | None]:
    """Run the launcher as the grader does: exit status, output, errors, and what it wrote on
    its status pipe (None when nothing: the exec happened)."""
    read, write = os.pipe()
    try:
        run = subprocess.Popen(
            module_command("autograder.sandbox.contained.launcher",
                           [json.dumps({**spec, "status_fd": write}), "--", *command]),
            cwd=SAFE_CWD, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
            pass_fds=(write,))
    finally:
        os.close(write)
    with os.fdopen(read, "rb") as status:
        written = status.read()  # until the exec closes it, or the launcher exits
    out, err = run.communicate(timeout=timeout)
    return run.returncode, out, err, json.loads(written) if written else None


def test_a_program_runs_in_its_folder_with_its_limits_and_no_new_privileges(tmp_path):
    status, out, err, failure = _launch({"limits": LIMITS, "workdir": str(tmp_path)},
                                        [sys.executable, "-c", SHOW_SELF])
    assert (status, failure) == (0, None), err
    seen = json.loads(out)
    assert seen["cwd"] == str(tmp_path)  # the launcher itself started from /
    assert seen["no_new_privs"] == "1"
    mb = 1024 * 1024
    assert seen["limits"] == {
        "RLIMIT_CPU": 7, "RLIMIT_AS": 900 * mb, "RLIMIT_NOFILE": 99, "RLIMIT_FSIZE": 3 * mb,
        "RLIMIT_CORE": 0,  # never a core dump in the student's folder
        # Root is exempt from RLIMIT_NPROC (the pids cgroup counts); any other user's
        # allowance is on top of what that user already runs.
        "RLIMIT_NPROC": (resource.getrlimit(resource.RLIMIT_NPROC)[0] if os.geteuid() == 0
                         else seen["limits"]["RLIMIT_NPROC"])}
    if os.geteuid() != 0:
        assert seen["limits"]["RLIMIT_NPROC"] >= 77


@pytest.mark.parametrize(("spec", "command", "stage", "error"), [
    ({"cgroups": ["/nonexistent/run-cgroup"]}, [sys.executable, "-c", "print('ran')"],
     "cgroup", "FileNotFoundError"),
    ({}, ["/nonexistent/python3", "-c", "print('ran')"], "exec /nonexistent/python3",
     "FileNotFoundError"),
    ({"limits": {"open_files": -5}}, [sys.executable, "-c", "print('ran')"],
     "resource limits", "ValueError"),
])
def test_a_failure_before_the_exec_names_its_stage_and_runs_nothing(tmp_path, spec, command,
                                                                    stage, error):
    status, out, _err, failure = _launch({"workdir": str(tmp_path), **spec}, command)
    assert status == LAUNCH_FAILED
    assert failure is not None and failure["stage"] == stage, failure
    assert failure["error"].startswith(f"{error}: ")
    assert "ran" not in out


def test_without_a_status_pipe_the_failure_is_on_its_errors(tmp_path):
    run = subprocess.run(
        module_command("autograder.sandbox.contained.launcher", [
            json.dumps({"workdir": str(tmp_path / "missing")}), "--", sys.executable, "-c", ""]),
        cwd=SAFE_CWD, capture_output=True, text=True, timeout=120)
    assert run.returncode == LAUNCH_FAILED
    report = json.loads(run.stderr.strip().splitlines()[-1])
    assert report["stage"] == "working directory"
    assert report["error"].startswith("FileNotFoundError")


def _strict() -> bool:
    from autograder.sandbox.isolation import detect

    return os.geteuid() == 0 and detect().strict


SHOW_STRICT = SHOW_SELF + """\
import sys
def listing(path):
    try:
        return sorted(os.listdir(path))
    except OSError as exc:
        return type(exc).__name__
owners = set()
for name in os.listdir("/proc"):
    if name.isdigit():
        try:
            owners.add(os.stat("/proc/" + name).st_uid)
        except OSError:
            pass
staged = os.stat("staged.txt")
mounts = open("/proc/self/mountinfo").read()
print(json.dumps({"hidden": listing(sys.argv[1]), "checkout": listing(sys.argv[2]),
                  "tmp": listing("/tmp"), "proc_owners": sorted(owners),
                  "staged": [open("staged.txt").read(), staged.st_uid],
                  "workdir_fs": mounts.count(" " + os.getcwd() + " ")}))
"""


@pytest.mark.skipif(not _strict(), reason="needs root and strict isolation")
def test_strict_a_user_a_tmp_and_a_proc_of_its_own_and_the_course_out_of_sight(tmp_path):
    from autograder.sandbox.domains import hold_domain
    from autograder.sandbox.isolation import student_uid

    hidden = tmp_path / "hidden"
    hidden.mkdir()
    (hidden / "solution.py").write_text("secret\n")
    workdir = Path(tempfile.mkdtemp(prefix="autograder-student-", dir="/tmp"))
    try:
        (workdir / "staged.txt").write_text("staged\n")
        with hold_domain() as lock:
            uid = student_uid(lock.domain)
            status, out, err, failure = _launch(
                {"limits": LIMITS, "workdir": str(workdir), "uid": uid, "hide": [str(hidden)],
                 "workdir_mb": 8},
                [sys.executable, "-c", SHOW_STRICT, str(hidden), PACKAGE_PARENT])
        assert (status, failure) == (0, None), err
        first, second = (json.loads(line) for line in out.splitlines())
        assert (first["uid"], first["gid"], first["groups"]) == (uid, uid, [])
        assert first["cwd"] == str(workdir) and first["no_new_privs"] == "1"
        assert first["limits"]["RLIMIT_NPROC"] == 77  # its own user: counted from zero
        # Out of sight: covered (mode 000), or under a /tmp of its own.
        assert second["hidden"] in ("PermissionError", "FileNotFoundError")
        assert second["checkout"] in ("PermissionError", "FileNotFoundError")
        assert workdir.name in second["tmp"]  # a fresh /tmp: no other run's files
        assert tmp_path.relative_to("/tmp").parts[0] not in second["tmp"]
        assert second["proc_owners"] == [uid]  # only its own processes
        assert second["staged"] == ["staged\n", uid]
        assert second["workdir_fs"] == 1  # its folder is a mount (tmpfs) of its own
        assert (hidden / "solution.py").read_text() == "secret\n"  # the grader's view kept
    finally:
        subprocess.run(["rm", "-rf", str(workdir)], check=False)


def test_apply_limits_in_a_child():
    """As the launcher applies them: each limit scaled to its unit, soft and hard alike;
    ``processes`` for a user of its own as given."""
    code = ("import json, resource, sys\n"
            "from autograder.sandbox.contained.launcher import apply_limits\n"
            "apply_limits(json.loads(sys.argv[1]))\n"
            "print(json.dumps([resource.getrlimit(resource.RLIMIT_AS),"
            " resource.getrlimit(resource.RLIMIT_NPROC), resource.getrlimit(resource.RLIMIT_CORE),"
            " resource.getrlimit(resource.RLIMIT_CPU)]))\n")
    run = subprocess.run([sys.executable, "-c", code,
                          json.dumps({"memory_mb": 700, "processes": 33, "uid": 12345})],
                         capture_output=True, text=True, timeout=60, check=True)
    memory, processes, core, cpu = json.loads(run.stdout)
    assert memory == [700 * 1024 * 1024] * 2
    assert processes == [33, 33]
    assert core == [0, 0]
    assert cpu == list(resource.getrlimit(resource.RLIMIT_CPU))  # not given: unchanged
    assert callable(apply_limits)


def test_user_tasks_counts_threads_as_rlimit_nproc_does(tmp_path):
    """Without a uid of its own, a student's RLIMIT_NPROC is what its user already runs plus
    its own allowance, so the count is of threads (as RLIMIT_NPROC counts), by real uid."""

    def process(pid: str, uids: str, threads: int | None) -> None:
        (tmp_path / pid).mkdir()
        lines = ["Name:\tpython3", "State:\tS (sleeping)", f"Uid:\t{uids}"] + \
            ([f"Threads:\t{threads}"] if threads is not None else [])
        (tmp_path / pid / "status").write_text("\n".join(lines) + "\n")

    process("10", "1000\t1000\t1000\t1000", 3)
    process("11", "1000\t0\t0\t0", 4)  # real uid 1000, set-uid root: counted
    process("12", "0\t1000\t1000\t1000", 9)  # real uid root: not counted
    process("13", "1000\t1000\t1000\t1000", None)  # a short status: skipped
    (tmp_path / "14").mkdir()  # gone between listing and reading
    (tmp_path / "self").mkdir()
    assert sorted(process_statuses(str(tmp_path))) == [
        (10, 1000, b"S", 3), (11, 1000, b"S", 4), (12, 0, b"S", 9)]
    assert user_tasks(1000, str(tmp_path)) == 7
    # Live: this process's own threads are among its user's.
    assert user_tasks(os.getuid()) >= len(os.listdir("/proc/self/task"))
    assert (os.getpid(), os.getuid(), b"R", len(os.listdir("/proc/self/task"))) in \
        set(process_statuses())


def test_the_barrier_above_a_needed_path(monkeypatch):
    """The topmost folder the student would not get through: a fresh one (/tmp), else one
    closed to other users; none for a path open all the way."""
    assert launcher.barrier_above("/tmp/venv/bin/python3") == "/tmp"
    assert launcher.barrier_above("/usr/lib") is None
    monkeypatch.setattr(launcher, "FRESH", ())
    closed = tempfile.mkdtemp(dir="/tmp")  # 0700
    try:
        os.makedirs(os.path.join(closed, "venv", "lib"))
        assert launcher.barrier_above(os.path.join(closed, "venv", "lib")) == closed
        os.chmod(closed, 0o755)
        assert launcher.barrier_above(os.path.join(closed, "venv", "lib")) is None
    finally:
        subprocess.run(["rm", "-rf", closed], check=False)


def test_interpreter_paths_are_the_interpreters_not_the_checkouts(monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "path", [*sys.path, str(tmp_path), PACKAGE_PARENT, "relative"])
    monkeypatch.setenv("LD_LIBRARY_PATH", os.pathsep.join([str(tmp_path / "lib"), "/usr/lib"]))
    paths = interpreter_paths()
    assert sys.prefix in paths and sys.base_prefix in paths
    assert os.path.dirname(os.path.realpath(sys.executable)) in paths
    assert "/usr/lib" in paths
    # Neither this platform's checkout nor the folder it runs from; nothing relative or missing.
    assert PACKAGE_PARENT not in paths and str(tmp_path) not in paths
    assert "relative" not in paths and str(tmp_path / "lib") not in paths
