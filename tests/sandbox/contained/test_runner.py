"""The runner: a student's script run through :func:`runner.command` behaves as
``python script args...`` would (argv, ``__main__``, its folder first on the module path, the
exit status of an exception or of Ctrl-C), with a shorter thread switch interval and the
signals a terminal gives, whatever the grader's were."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
from pathlib import Path

from autograder.sandbox.contained import runner
from autograder.sandbox.contained.runner import SWITCH_INTERVAL, command

SHOW_SELF = """\
import json, os, signal, sys
print(json.dumps({
    "argv": sys.argv, "name": __name__, "file": __file__, "path0": sys.path[0],
    "switch": sys.getswitchinterval(),
    "blocked": sorted(int(s) for s in signal.pthread_sigmask(signal.SIG_BLOCK, [])),
    "sigint": signal.getsignal(signal.SIGINT) is signal.default_int_handler,
    "sigpipe": signal.getsignal(signal.SIGPIPE) == signal.SIG_IGN,
    "sigxfsz": signal.getsignal(signal.SIGXFSZ) == signal.SIG_IGN,
    "sigterm": signal.getsignal(signal.SIGTERM) == signal.SIG_DFL,
    "sighup": signal.getsignal(signal.SIGHUP) == signal.SIG_DFL,
}))
"""


def _script(tmp_path: Path, text: str) -> Path:
    script = tmp_path / "node.py"
    script.write_text(text)
    return script


def _run(script: Path, args: list[str], **popen: object) -> subprocess.CompletedProcess[str]:
    return subprocess.run(command(sys.executable, str(script), args), capture_output=True,
                          text=True, timeout=120, **popen)  # type: ignore[call-overload]


def _grader_signals() -> None:
    """A grader started in the background: SIGINT and SIGTERM ignored, SIGHUP blocked."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    signal.pthread_sigmask(signal.SIG_BLOCK, [signal.SIGHUP])


def test_the_command_runs_this_modules_source_on_the_script():
    python, flag, source, script, *args = command("/usr/bin/python3", "/w/node.py", ["-a", "b"])
    assert (python, flag, script, args) == ("/usr/bin/python3", "-c", "/w/node.py", ["-a", "b"])
    assert source.startswith(Path(runner.__file__).read_text(encoding="utf-8"))
    assert source.rstrip().endswith("run_program(sys.argv[1], sys.argv[2:])")


def test_a_script_sees_itself_as_python_script_shows_it(tmp_path):
    script = _script(tmp_path, SHOW_SELF)
    run = _run(script, ["--ros-args", "-p", "x:=1"], cwd="/",
               preexec_fn=_grader_signals)  # the test's own process, not a threaded grader
    assert run.returncode == 0, run.stderr
    seen = json.loads(run.stdout)
    assert seen["argv"] == [str(script), "--ros-args", "-p", "x:=1"]
    assert (seen["name"], seen["file"], seen["path0"]) == ("__main__", str(script),
                                                          str(tmp_path))
    assert seen["switch"] == SWITCH_INTERVAL < 0.005
    # The signals of `python script.py` from a terminal, not the grader's.
    assert seen["blocked"] == []
    assert seen["sigint"] and seen["sigpipe"] and seen["sigxfsz"]
    assert seen["sigterm"] and seen["sighup"]


def test_a_sibling_module_is_imported_from_the_scripts_folder(tmp_path):
    (tmp_path / "helper.py").write_text("VALUE = 'beside the node'\n")
    run = _run(_script(tmp_path, "import helper\nprint(helper.VALUE)\n"), [], cwd="/")
    assert (run.returncode, run.stdout) == (0, "beside the node\n"), run.stderr


def test_an_exception_is_status_1_with_the_students_frames_only(tmp_path):
    script = _script(tmp_path, "def callback():\n    raise ValueError('boom')\ncallback()\n")
    run = _run(script, [])
    assert run.returncode == 1
    assert run.stderr.startswith("Traceback (most recent call last):\n")
    assert f'File "{script}", line 3, in <module>' in run.stderr
    assert "ValueError: boom" in run.stderr
    assert "run_program" not in run.stderr and '"<string>"' not in run.stderr


def test_system_exit_keeps_its_status(tmp_path):
    run = _run(_script(tmp_path, "import sys\nprint('bye')\nsys.exit(3)\n"), [])
    assert (run.returncode, run.stdout, run.stderr) == (3, "bye\n", "")


def test_keyboard_interrupt_ends_it_by_sigint_after_its_exit_handlers(tmp_path):
    script = _script(tmp_path, (
        "import atexit\n"
        "atexit.register(lambda: print('exit handler', flush=True))\n"
        "raise KeyboardInterrupt\n"))
    run = _run(script, [], preexec_fn=_grader_signals)
    assert run.returncode == -signal.SIGINT  # as CPython ends on an unhandled Ctrl-C
    assert run.stdout == "exit handler\n"
    assert "KeyboardInterrupt" in run.stderr and "run_program" not in run.stderr


def test_a_syntax_error_is_reported_as_the_interpreter_would(tmp_path):
    run = _run(_script(tmp_path, "def broken(:\n"), [])
    assert run.returncode == 1
    assert "SyntaxError" in run.stderr and str(tmp_path / "node.py") in run.stderr
