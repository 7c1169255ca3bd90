"""The scale-out recipes work as printed: the Kubernetes Jobs and the GitHub shard workflow
are rendered, parsed, and their commands run as a pod or a runner would run them.

As in the pod: the commands run as root, from ``/``, with a PATH that has no ``unshare``
(so isolation is by user, as in an unprivileged pod), no cgroup the platform can create
(``AUTOGRADER_CGROUP_ROOT`` is a file), the course on a path of its own found only through
``AUTOGRADER_COURSE``, and the platform installed by the printed ``pip install`` into a
fresh virtual environment. Only the install's source changes: the printed git URL becomes
a copy of this checkout, so what is tested is the code at hand. A fresh venv plus that
install takes about 10 s here (pip's cache and the local indexes), so each run makes a
real one rather than borrowing the project's venv. Steps that only bring files (volumes,
git-sync, ``actions/checkout``, artifacts) are done by the test, from their YAML.

Everything lives in a folder of mode 0755 under /tmp, not pytest's 0700 one, as a
course's folders would on a pod's volume.
"""

from __future__ import annotations

import csv
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml
from test_batch import EXPECTED, KINDS, VARIANTS

from autograder.commands.workflows import render_workflow

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parent.parent
COURSE = ROOT / "tests" / "fixtures" / "mini_course"
CLASS = {f"student{i:02d}": kind for i, kind in enumerate(KINDS[:6])}
VALUES = {"exercise": "shout", "submission": ".", "shards": 2,
          "platform_repo": "https://example.invalid/platform",
          "hidden_repo": "course/hidden-tests", "claim": "grading-data"}
PRINTED_SOURCE = f'"rclpy-autograder @ git+{VALUES["platform_repo"]}"'
# The PATH of the python:3.11 image, mirrored without unshare.
IMAGE_PATH = ("/usr/local/sbin", "/usr/local/bin", "/usr/sbin", "/usr/bin", "/sbin", "/bin")


@pytest.fixture(scope="module")
def root_dir() -> Iterator[Path]:
    if os.geteuid() != 0:
        pytest.skip("the pod's grader runs as root")
    folder = Path(tempfile.mkdtemp(prefix="autograder-scaleout-"))
    folder.chmod(0o755)
    yield folder
    shutil.rmtree(folder, ignore_errors=True)


@pytest.fixture(scope="module")
def venv(root_dir: Path) -> Path:
    """An empty venv from the base interpreter: the image's Python before the install."""
    python = Path(sys.base_prefix) / "bin" / "python3"
    subprocess.run([str(python), "-m", "venv", str(root_dir / "venv")], check=True)
    return root_dir / "venv"


@pytest.fixture(scope="module")
def platform(root_dir: Path) -> Path:
    """What the platform's git URL brings: the package sources, copied because pip builds
    in the source tree (a build/ folder) and the checkout must stay clean."""
    copy = root_dir / "platform"
    copy.mkdir()
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc")
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(ROOT / name, copy / name)
    for name in ("autograder", "content", "sim"):
        shutil.copytree(ROOT / name, copy / name, ignore=ignore)
    return copy


@pytest.fixture(scope="module")
def base_env(root_dir: Path, venv: Path) -> dict[str, str]:
    """The environment of a root shell in the pod: no unshare, no cgroups to make."""
    bin_dir = root_dir / "bin"
    bin_dir.mkdir()
    for folder in map(Path, IMAGE_PATH):
        for tool in sorted(folder.glob("*")) if folder.is_dir() else []:
            if tool.name != "unshare" and not (bin_dir / tool.name).exists():
                (bin_dir / tool.name).symlink_to(tool)
    no_cgroups = root_dir / "no-cgroups"
    no_cgroups.write_text("a file: no cgroup can be made under it\n")
    env = {"PATH": f"{venv / 'bin'}:{bin_dir}", "HOME": os.environ.get("HOME", "/root"),
           "LANG": "C.UTF-8", "AUTOGRADER_CGROUP_ROOT": str(no_cgroups)}
    # pip's settings here point at the machine's local indexes: the pod's network.
    env.update({k: v for k, v in os.environ.items() if k.startswith("PIP_")})
    assert shutil.which("unshare", path=env["PATH"]) is None
    return env


def make_submissions(folder: Path) -> None:
    """Half the class as a student's folder, half as a bare file (as in test_batch)."""
    folder.mkdir(parents=True)
    for i, (student, kind) in enumerate(CLASS.items()):
        if i % 2:
            (folder / student).mkdir()
            (folder / student / "shouter.py").write_text(VARIANTS[kind])
        else:
            (folder / f"{student}.py").write_text(VARIANTS[kind])


def local_install(script: str, platform: Path) -> str:
    """The printed script with only its pip install's source swapped for this checkout."""
    assert PRINTED_SOURCE in script, script
    return script.replace(PRINTED_SOURCE, f'"rclpy-autograder @ {platform.as_uri()}"')


def run(argv: list[str], env: dict[str, str], cwd: Path) -> str:
    proc = subprocess.run(argv, env=env, cwd=cwd, capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, f"{argv}\n{proc.stdout}\n{proc.stderr}"
    return proc.stdout


def scores(book: Path) -> dict[str, str]:
    with book.open() as fh:
        rows = list(csv.DictReader(fh))
    assert all(row["item"] == "shout" and row["max_score"] == "3" for row in rows)
    return {row["student"]: row["score"] for row in rows}


def graded_as_in_the_pod(reports: Path) -> set[str]:
    """The students with results in ``reports``, each graded in isolation by user (there
    is no unshare: no namespaces, a user of its own all the same), officially, and without
    a grader error."""
    graded = set()
    for path in reports.glob("*/results.json"):
        result = json.loads(path.read_text())
        assert result["isolation"]["mode"] == "user", result["isolation"]
        assert result["isolation"]["official"] is True
        assert result.get("grader_error") is None, result
        graded.add(path.parent.name)
    return graded


# --- Kubernetes -------------------------------------------------------------------------

def remap(text: str, mounts: dict[str, Path]) -> str:
    """Paths in the pod (under its volume mounts) as paths on this machine."""
    for mount, local in mounts.items():
        text = re.sub(rf"(?<![\w./-]){re.escape(mount)}(?![\w.-])", str(local), text)
    return text


def fetch_course(link: Path) -> None:
    """What git-sync leaves: a worktree, and the --link symlink to it."""
    worktree = link.parent / ".worktrees" / "0123abcd"
    shutil.copytree(COURSE, worktree)
    link.symlink_to(worktree.relative_to(link.parent))


def run_container(container: dict[str, Any], mounts: dict[str, Path], env: dict[str, str],
                  platform: Path) -> str:
    script = local_install(remap(container["args"][0], mounts), platform)
    env = dict(env, **{e["name"]: remap(e["value"], mounts) for e in container.get("env", [])})
    return run([*container["command"], script], env, Path("/"))


def test_kubernetes_jobs_as_printed(root_dir: Path, base_env: dict[str, str],
                                    platform: Path) -> None:
    grading, merging = yaml.safe_load_all(render_workflow("k8s-shards", **VALUES))
    pod = grading["spec"]["template"]["spec"]
    volumes = {v["name"]: v for v in pod["volumes"]}
    (sync,), (grader,) = pod["initContainers"], pod["containers"]
    grader_mounts = {m["name"]: m["mountPath"] for m in grader["volumeMounts"]}
    sync_mounts = {m["name"]: m["mountPath"] for m in sync["volumeMounts"]}
    flags = dict(arg.removeprefix("--").partition("=")[::2] for arg in sync["args"])

    # The course comes from the private repo into a pod-local volume, where the grader
    # looks; the token that reads the repo is not mounted in the grader.
    assert flags["repo"].endswith(VALUES["hidden_repo"]) and "one-time" in flags
    course_volume = next(n for n, path in sync_mounts.items() if path == flags["root"])
    assert "emptyDir" in volumes[course_volume]
    assert grader_mounts[course_volume] == flags["root"]
    env = {e["name"]: e["value"] for e in grader["env"]}
    assert env["AUTOGRADER_COURSE"] == f"{flags['root']}/{flags['link']}"
    secrets = {n for n, v in volumes.items() if "secret" in v}
    assert secrets and secrets <= set(sync_mounts) and not secrets & set(grader_mounts)
    assert grader["resources"]["limits"]["memory"]

    here = root_dir / "k8s"
    mounts = {path: here / name for name, path in grader_mounts.items()}
    fetch_course(mounts[flags["root"]] / flags["link"])
    data = mounts["/data"]
    make_submissions(data / "submissions")
    for index in range(grading["spec"]["completions"]):
        run_container(grader, mounts, dict(base_env, JOB_COMPLETION_INDEX=str(index)),
                      platform)
        assert scores(data / "out" / f"gradebook-{index}.csv")  # each shard has students
    assert mounts[flags["root"]].stat().st_mode & 0o777 == 0o700
    assert graded_as_in_the_pod(data / "out" / "reports") == set(CLASS)

    assert merging["spec"]["suspend"] is True  # started once the grading Job completes
    (merger,) = merging["spec"]["template"]["spec"]["containers"]
    assert "course" not in {m["name"] for m in merger["volumeMounts"]}
    run_container(merger, {m["mountPath"]: here / m["name"] for m in merger["volumeMounts"]},
                  base_env, platform)
    assert scores(data / "out" / "gradebook.csv") == {
        student: EXPECTED[kind] for student, kind in CLASS.items()}


# --- GitHub Actions ---------------------------------------------------------------------

def expand(text: str, context: dict[str, str]) -> str:
    """GitHub's ${{ name }} expressions; one this test does not know fails it."""
    return re.sub(r"\$\{\{\s*([\w.]+)\s*\}\}", lambda m: context[m.group(1)], text)


class Runner:
    """Runs a job's steps as a runner would: ``run:`` steps as ``bash -e`` scripts in the
    workspace; the ``uses:`` actions it knows are done here, on files."""

    def __init__(self, workspace: Path, env: dict[str, str], platform: Path,
                 artifacts: Path, submissions: Path) -> None:
        self.workspace, self.env, self.platform = workspace, env, platform
        self.artifacts, self.submissions = artifacts, submissions
        workspace.mkdir(parents=True)

    def job(self, steps: list[dict[str, Any]], context: dict[str, str]) -> None:
        context = dict(context, **{"github.workspace": str(self.workspace)})
        for step in steps:
            if "uses" in step:
                self.action(step["uses"].partition("@")[0], step.get("with", {}), context)
            else:
                self.script(step, context)

    def script(self, step: dict[str, Any], context: dict[str, str]) -> None:
        script = expand(step["run"], context)
        if "pip install" in script:
            script = local_install(script, self.platform)
        path = self.workspace.parent / f".step-{self.workspace.name}.sh"
        path.write_text(script)
        env = dict(self.env, **{k: expand(str(v), context)
                                for k, v in step.get("env", {}).items()})
        run(["bash", "-e", str(path)], env, self.workspace)

    def action(self, name: str, inputs: dict[str, Any], context: dict[str, str]) -> None:
        if name == "actions/checkout" and "repository" not in inputs:
            shutil.copytree(self.submissions, self.workspace / "submissions")
        elif name == "actions/checkout":  # the private course repository
            assert inputs["repository"] == VALUES["hidden_repo"]
            assert inputs["token"] == "${{ secrets.HIDDEN_TESTS_TOKEN }}"
            assert inputs["persist-credentials"] is False
            shutil.copytree(COURSE, self.workspace / inputs["path"])
        elif name == "actions/setup-python":
            pass  # the fresh venv is first on PATH
        elif name == "actions/upload-artifact":
            into = self.artifacts / expand(inputs["name"], context)
            for pattern in inputs["path"].split():
                for found in self.workspace.glob(pattern.rstrip("/")):
                    target = into / found.relative_to(self.workspace)
                    target.parent.mkdir(parents=True, exist_ok=True)
                    (shutil.copytree if found.is_dir() else shutil.copy)(found, target)
        elif name == "actions/download-artifact":
            assert inputs["merge-multiple"] is True
            for artifact in self.artifacts.iterdir():
                shutil.copytree(artifact, self.workspace / inputs["path"], dirs_exist_ok=True)
        else:
            raise AssertionError(f"an action this test does not know: {name}")


RUNNER_UID = 1001


@pytest.fixture(scope="module")
def runner_user_env(root_dir: Path, base_env: dict[str, str]) -> dict[str, str]:
    """The runner user of GitHub's runners, as the grading step sees it: ``id`` says 1001,
    and ``sudo`` asks no password and resets PATH (to the image's, without the venv) but
    keeps the rest of the environment with ``--preserve-env``. We stay root underneath."""
    fakes = root_dir / "runner-user"
    fakes.mkdir()
    secure_path = base_env["PATH"].split(":", 1)[1]
    (fakes / "id").write_text(f"""#!/bin/bash
case "$1" in -u|-g) echo {RUNNER_UID} ;; *) exec {shutil.which("id")} "$@" ;; esac
""")
    (fakes / "sudo").write_text(f"""#!/bin/bash
keep=""
while [[ "$1" == -* ]]; do [[ "$1" == --preserve-env ]] && keep=1; shift; done
if [ -n "$keep" ]; then exec env PATH={secure_path} "$@"; fi
exec env -i PATH={secure_path} "$@"
""")
    for fake in fakes.iterdir():
        fake.chmod(0o755)
    return dict(base_env, PATH=f"{fakes}:{base_env['PATH']}")


def test_github_shards_as_printed(root_dir: Path, base_env: dict[str, str],
                                  runner_user_env: dict[str, str], platform: Path) -> None:
    """Shard 1 runs as root (a self-hosted runner), shard 2 as the runner user with sudo
    (GitHub's own runners)."""
    flow = yaml.safe_load(render_workflow("github-shards", **VALUES))
    here = root_dir / "github"
    make_submissions(here / "repository")
    artifacts = here / "artifacts"
    graded: set[str] = set()
    for shard, env in zip(flow["jobs"]["shard"]["strategy"]["matrix"]["shard"],
                          (base_env, runner_user_env), strict=True):
        runner = Runner(here / f"shard-{shard}", env, platform, artifacts,
                        here / "repository")
        runner.job(flow["jobs"]["shard"]["steps"], {"matrix.shard": str(shard)})
        owners = {p.stat().st_uid for p in (runner.workspace / "reports").rglob("*")}
        assert owners == {0 if env is base_env else RUNNER_UID}  # sudo's files given back
        share = graded_as_in_the_pod(runner.workspace / "reports")
        assert share and not share & graded
        graded |= share
    assert graded == set(CLASS)
    uploaded = {p.name for p in artifacts.rglob("*")}
    hidden = {p.name for p in (COURSE / "assignments/shout/tests/hidden").iterdir()}
    assert uploaded and not uploaded & (hidden | {"assignments", "course"})

    merger = Runner(here / "merge", base_env, platform, artifacts, here / "repository")
    merger.job(flow["jobs"]["merge"]["steps"], {})
    assert scores(merger.workspace / "gradebook.csv") == {
        student: EXPECTED[kind] for student, kind in CLASS.items()}
    assert (artifacts / "gradebook" / "gradebook.csv").exists()

