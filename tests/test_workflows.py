"""The CI templates render to valid YAML that runs our commands, and keep secrets where
students' programs are not: none in a student's repository, a token only in the step that
fetches the course."""

import os
import subprocess
from pathlib import Path
from typing import Any

import yaml
from click.testing import CliRunner

from autograder.cli import main
from autograder.commands.workflows import render_workflow

VALUES = {"exercise": "timer_sync", "submission": "src", "shards": 5,
          "platform_repo": "https://example.invalid/platform", "hidden_repo": "course/hidden",
          "claim": "data"}


def runs(steps: list[dict[str, Any]]) -> str:
    return " ".join(s.get("run", "") for s in steps)


# --- a student's repository --------------------------------------------------------------

def test_student_workflow_runs_the_public_tests_and_names_no_secret():
    text = render_workflow("github-student", **VALUES)
    assert "secrets." not in text and "token" not in text.lower()
    assert VALUES["hidden_repo"] not in text
    flow = yaml.safe_load(text)
    assert flow["permissions"] == {"contents": "read"}
    steps = flow["jobs"]["grade"]["steps"]
    assert "autograder check timer_sync src" in runs(steps)
    assert "autograder grade " not in runs(steps)
    checkouts = [s for s in steps if s.get("uses", "").startswith("actions/checkout")]
    assert [c["with"] for c in checkouts] == [{"persist-credentials": False}]
    assert not any("env" in s for s in steps)


def test_the_hidden_repo_option_does_not_reach_the_student_workflow():
    plain = CliRunner().invoke(main, ["workflow", "github-student"])
    named = CliRunner().invoke(main, ["workflow", "github-student",
                                      "--hidden-repo", "course/secret-tests"])
    assert plain.exit_code == named.exit_code == 0
    assert plain.output == named.output


def test_workflow_help_says_where_hidden_tests_run():
    text = " ".join(CliRunner().invoke(main, ["workflow", "--help"]).output.split())
    assert "public tests only" in text
    assert "github-shards" in text and "Gradescope" in text and "k8s-shards" in text


# --- the course's repository -------------------------------------------------------------

def test_github_matrix_shards_and_merges():
    flow = yaml.safe_load(render_workflow("github-shards", **VALUES))
    assert flow["jobs"]["shard"]["strategy"]["matrix"]["shard"] == [1, 2, 3, 4, 5]
    assert "--shard ${{ matrix.shard }}/5" in runs(flow["jobs"]["shard"]["steps"])
    course = next(s for s in flow["jobs"]["shard"]["steps"]
                  if s.get("with", {}).get("repository") == "course/hidden")
    assert course["with"]["path"] == "course"
    grading = next(s for s in flow["jobs"]["shard"]["steps"] if "grade-batch" in s.get("run", ""))
    assert grading["env"]["AUTOGRADER_COURSE"] == "${{ github.workspace }}/course"
    assert "autograder gradebook merge gradebook.csv" in runs(flow["jobs"]["merge"]["steps"])
    assert flow["jobs"]["merge"]["needs"] == "shard"


def test_github_shards_token_only_in_the_fetch_before_grading():
    text = render_workflow("github-shards", **VALUES)
    flow = yaml.safe_load(text)
    assert flow["permissions"] == {"contents": "read"}
    steps = flow["jobs"]["shard"]["steps"]
    naming = [i for i, s in enumerate(steps) if "secrets." in yaml.safe_dump(s)]
    assert text.count("secrets.") == 1 and len(naming) == 1
    fetch = steps[naming[0]]
    assert fetch["with"]["token"] == "${{ secrets.HIDDEN_TESTS_TOKEN }}"
    assert fetch["with"]["repository"] == VALUES["hidden_repo"]
    grading = next(i for i, s in enumerate(steps) if "grade-batch" in s.get("run", ""))
    assert naming[0] < grading
    assert set(steps[grading]["env"]) == {"AUTOGRADER_COURSE"}
    for job in flow["jobs"].values():
        for step in job["steps"]:
            if step.get("uses", "").startswith("actions/checkout"):
                assert step["with"]["persist-credentials"] is False


def test_github_shards_never_grades_as_the_runner_user(tmp_path: Path):
    """Without root or sudo the grading step stops before grading anything: students'
    programs would run as the runner user, who can read course/ and the network."""
    flow = yaml.safe_load(render_workflow("github-shards", **VALUES))
    step = next(s for s in flow["jobs"]["shard"]["steps"] if "grade-batch" in s.get("run", ""))
    script = tmp_path / "step.sh"
    script.write_text(step["run"].replace("${{ matrix.shard }}", "1"))
    fakes = {"id": "echo 1001", "sudo": "exit 1",  # the runner user, who may not sudo
             "autograder": f"touch {tmp_path / 'graded'}"}
    for name, body in fakes.items():
        (tmp_path / name).write_text(f"#!/bin/sh\n{body}\n")
        (tmp_path / name).chmod(0o755)
    proc = subprocess.run(["bash", "-e", str(script)], capture_output=True, text=True,
                          cwd=tmp_path, env=dict(os.environ, PATH=f"{tmp_path}:/usr/bin:/bin"))
    assert proc.returncode == 1
    assert "::error::Grading needs root or sudo" in proc.stdout
    assert not (tmp_path / "graded").exists()


# --- Kubernetes -------------------------------------------------------------------------

def test_kubernetes_indexed_job_and_merge_job():
    job, merge = yaml.safe_load_all(render_workflow("k8s-shards", **VALUES))
    assert job["kind"] == "Job" and job["spec"]["completionMode"] == "Indexed"
    assert job["spec"]["completions"] == job["spec"]["parallelism"] == 5
    grader = job["spec"]["template"]["spec"]["containers"][0]
    assert "--shard $((JOB_COMPLETION_INDEX + 1))/5" in grader["args"][0]
    assert {"name": "AUTOGRADER_COURSE", "value": "/course/tree"} in grader["env"]
    assert job["metadata"]["name"] == "grade-timer-sync"
    assert merge["kind"] == "Job" and merge["metadata"]["name"] == "merge-timer-sync"
    assert "autograder gradebook merge" in merge["spec"]["template"]["spec"]["containers"][0][
        "args"][0]


def test_cli_prints_a_workflow():
    result = CliRunner().invoke(main, ["workflow", "k8s-shards", "--shards", "2"])
    assert result.exit_code == 0
    assert next(yaml.safe_load_all(result.output))["spec"]["completions"] == 2
