"""The CI templates render to valid YAML that runs our commands."""

import yaml
from click.testing import CliRunner

from autograder.cli import main
from autograder.commands.workflows import render_workflow

VALUES = {"exercise": "timer_sync", "submission": "src", "shards": 5,
          "platform_repo": "https://example.invalid/platform", "hidden_repo": "course/hidden",
          "claim": "data"}


def test_student_workflow_runs_public_and_hidden_tests():
    text = render_workflow("github-student", **VALUES)
    flow = yaml.safe_load(text)
    steps = flow["jobs"]["grade"]["steps"]
    runs = " ".join(s.get("run", "") for s in steps)
    assert "autograder check timer_sync src" in runs
    assert "autograder grade timer_sync src" in runs
    assert "${{ secrets.HIDDEN_TESTS_TOKEN }}" in text
    assert any(s.get("with", {}).get("repository") == "course/hidden" for s in steps)


def test_github_matrix_shards_and_merges():
    flow = yaml.safe_load(render_workflow("github-shards", **VALUES))
    assert flow["jobs"]["shard"]["strategy"]["matrix"]["shard"] == [1, 2, 3, 4, 5]
    shard_runs = " ".join(s.get("run", "") for s in flow["jobs"]["shard"]["steps"])
    assert "--shard ${{ matrix.shard }}/5" in shard_runs
    course = next(s for s in flow["jobs"]["shard"]["steps"]
                  if s.get("with", {}).get("repository") == "course/hidden")
    assert course["with"]["path"] == "course"
    grading = next(s for s in flow["jobs"]["shard"]["steps"] if "grade-batch" in s.get("run", ""))
    assert grading["env"]["AUTOGRADER_COURSE"] == "${{ github.workspace }}/course"
    merge_runs = " ".join(s.get("run", "") for s in flow["jobs"]["merge"]["steps"])
    assert "autograder gradebook merge gradebook.csv" in merge_runs
    assert flow["jobs"]["merge"]["needs"] == "shard"


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
