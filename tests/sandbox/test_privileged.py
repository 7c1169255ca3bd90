"""Nothing of the student's is run or imported by a privileged process of the grader
(issue 28): modules named like the standard library's beside the node. What a program
leaves behind for its user, swept: tests/sandbox/test_sweep.py. Links, devices and FIFOs
in a submission, never followed or read: tests/core/test_submission.py."""

from __future__ import annotations

import ctypes
import os
import subprocess
import sys
from pathlib import Path

import pytest

from autograder.core.exercise import Limits
from autograder.sandbox.isolation import detect
from autograder.sandbox.privileged import SAFE_CWD, module_command
from autograder.sandbox.process import student_process

REPO = Path(__file__).resolve().parents[2]
COURSE = REPO / "tests" / "fixtures" / "mini_course"
SOLUTION = COURSE / "assignments" / "shout" / "solution" / "shouter.py"
SHADOWS = ("json", "ctypes", "resource", "sitecustomize", "usercustomize", "runpy")

strict_only = pytest.mark.skipif(not detect().strict,
                                 reason=f"needs strict isolation: {detect().reason}")


# -- a privileged Python never imports the student's modules --------------------------
def _shadowed(folder: Path) -> Path:
    """A program beside modules named like the standard library's: each says, if it is
    imported while the launcher is loading, that the launcher imported it."""
    for name in SHADOWS:
        (folder / f"{name}.py").write_text(
            "import sys\n"
            "if sys.argv[0].endswith('launcher.py') or 'autograder.sandbox' in sys.modules:\n"
            f"    print('LAUNCHER IMPORTED {name}', flush=True)\n"
            f"raise ImportError('shadow {name}')\n")
    script = folder / "program.py"
    script.write_text("print('PROGRAM RAN', flush=True)\n")
    return script


def test_the_privileged_command_is_isolated_and_names_no_student_folder():
    command = module_command("autograder.sandbox.contained.launcher", ["SPEC"])
    assert command[1] == "-I"  # no working directory, no PYTHON* variables, no user site
    assert SAFE_CWD == "/"


@pytest.mark.parametrize("strict", [False, pytest.param(True, marks=strict_only)])
def test_the_launcher_never_imports_a_module_beside_the_node(tmp_path, strict):
    staged = tmp_path / "staged"
    staged.mkdir()
    script = _shadowed(staged)
    process = student_process(script, [], Limits(), domain=0, strict=strict, course=COURSE)
    process.start()  # the launcher's own start: a shadow raising ImportError would break it
    assert process.wait(30) == 0
    process.stop()
    assert "PROGRAM RAN" in process.output_text()
    assert "LAUNCHER IMPORTED" not in process.output_text()


def test_an_isolated_command_ignores_the_folder_it_starts_in(tmp_path):
    """Even started from the student's folder (it never is: it starts from "/"), the
    isolated interpreter takes no module from there; a plain ``-c`` would."""
    _shadowed(tmp_path)
    for name in SHADOWS:  # say so whoever imports them
        (tmp_path / f"{name}.py").write_text(f"print('SHADOW {name} IMPORTED')\n")
    isolated = subprocess.run(module_command("autograder.sandbox.privileged", []),
                              capture_output=True, text=True, timeout=60, cwd=tmp_path)
    assert isolated.returncode == 0, isolated.stderr
    assert "IMPORTED" not in isolated.stdout + isolated.stderr
    plain = subprocess.run([sys.executable, "-c", "import json, runpy"], capture_output=True,
                           text=True, timeout=60, cwd=tmp_path)
    assert "SHADOW json IMPORTED" in plain.stdout  # the test can fail


@strict_only
def test_a_strict_program_sees_no_other_users_processes_and_gains_no_privileges(tmp_path):
    staged = tmp_path / "staged"
    staged.mkdir()
    script = staged / "program.py"
    script.write_text(
        "import os\n"
        "others = [p for p in os.listdir('/proc') if p.isdigit()\n"
        "          and os.stat(f'/proc/{p}').st_uid != os.getuid()]\n"
        "print('OTHERS', len(others))\n"
        "print(next(l for l in open('/proc/self/status') if l.startswith('NoNewPrivs')))\n")
    process = student_process(script, [], Limits(), domain=0, strict=True, course=COURSE)
    process.start()
    assert process.wait(30) == 0
    process.stop()
    output = process.output_text()
    assert "OTHERS 0" in output
    assert "NoNewPrivs:\t1" in output


@strict_only
def test_a_strict_programs_sysv_objects_are_its_own_namespaces(tmp_path):
    staged = tmp_path / "staged"
    staged.mkdir()
    script = staged / "program.py"
    key = 0x5A1B0000 + os.getpid() % 0x10000
    script.write_text("import ctypes\n"
                      f"print('SHM', ctypes.CDLL(None).shmget({key}, 4096, 0o1666))\n")
    process = student_process(script, [], Limits(), domain=0, strict=True, course=COURSE)
    process.start()
    assert process.wait(30) == 0
    process.stop()
    assert "SHM -1" not in process.output_text()  # it made one
    libc = ctypes.CDLL(None)
    assert libc.shmget(key, 0, 0) == -1  # and the machine has none under that key


def test_a_program_and_what_it_forks_share_one_cpu_group_of_their_own(tmp_path):
    """Where cpu cgroups can be made, the program and its children sit in one of their own,
    so its spinning children take one share from the gradings beside it, not six."""
    from autograder.sandbox.cgroups import Cgroup

    probe = Cgroup(f"cpu-check-{os.getpid()}", Limits())
    probe.remove()
    if "cpu" not in probe.controllers:
        pytest.skip("no writable cpu cgroup here")
    staged = tmp_path / "staged"
    staged.mkdir()
    script = staged / "program.py"
    script.write_text("import os\n"
                      "pid = os.fork()\n"
                      "if pid == 0:\n"
                      "    print('CHILD', open('/proc/self/cgroup').read(), flush=True)\n"
                      "    os._exit(0)\n"
                      "os.waitpid(pid, 0)\n"
                      "print('PARENT', open('/proc/self/cgroup').read(), flush=True)\n")
    process = student_process(script, [], Limits(), domain=0, strict=False, course=COURSE)
    process.start()
    assert process.wait(30) == 0
    cpu = [p for p in process.cgroup.paths if (p / "cpu.shares").exists()
           or (p / "cpu.weight").exists()]
    process.stop()
    assert len(cpu) == 1
    for who in ("CHILD", "PARENT"):
        section = process.output_text().split(who, 1)[1]
        lines = [line for line in section.splitlines()
                 if ":cpu" in line or line.startswith("0::")]
        assert any(line.endswith("/" + cpu[0].name) for line in lines), (who, lines)
