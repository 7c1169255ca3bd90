"""The CI templates render to valid YAML that runs our commands, and keep secrets where
students' programs are not: none in a student's repository, a token only in the step that
fetches the course, and Kubernetes pods that meet Pod Security baseline."""

import os
import subprocess
from pathlib import Path
from typing import Any

import kubernetes_validate
import pytest
import yaml
from click.testing import CliRunner
from pod_security import BASELINE, RESTRICTED, failures

from autograder.cli import main
from autograder.commands.workflows import render_workflow

VALUES = {"exercise": "timer_sync", "submission": "src", "shards": 5,
          "platform_repo": "https://example.invalid/platform", "hidden_repo": "course/hidden",
          "claim": "data"}
# The oldest and newest Kubernetes whose API schemas kubernetes-validate has.
K8S_VERSIONS = ("1.25", kubernetes_validate.latest_version())


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


# --- Kubernetes --------------------------------------------------------------------------

def k8s_jobs() -> tuple[dict[str, Any], dict[str, Any]]:
    grading, merging = yaml.safe_load_all(render_workflow("k8s-shards", **VALUES))
    return grading, merging


def test_kubernetes_indexed_job_and_merge_job():
    job, merge = k8s_jobs()
    assert job["kind"] == "Job" and job["spec"]["completionMode"] == "Indexed"
    assert job["spec"]["completions"] == job["spec"]["parallelism"] == 5
    grader = job["spec"]["template"]["spec"]["containers"][0]
    assert "--shard $((JOB_COMPLETION_INDEX + 1))/5" in grader["args"][0]
    assert {"name": "AUTOGRADER_COURSE", "value": "/course/tree"} in grader["env"]
    assert job["metadata"]["name"] == "grade-timer-sync"
    assert merge["kind"] == "Job" and merge["metadata"]["name"] == "merge-timer-sync"
    assert "autograder gradebook merge" in merge["spec"]["template"]["spec"]["containers"][0][
        "args"][0]


@pytest.mark.parametrize("version", K8S_VERSIONS)
def test_kubernetes_jobs_match_the_api_schema(version: str):
    for job in k8s_jobs():
        kubernetes_validate.validate(job, version, strict=True)


def test_kubernetes_jobs_meet_baseline_and_fail_restricted_only_for_root_and_capabilities():
    """What the recipe and the README say: baseline holds; restricted fails because the pods
    run as root (its two non-root checks) and the grader keeps five capabilities."""
    text = render_workflow("k8s-shards", **VALUES)
    assert "kubectl label namespace grading pod-security.kubernetes.io/enforce=baseline" in text
    grading, merging = k8s_jobs()
    assert failures(grading, BASELINE) == failures(merging, BASELINE) == set()
    assert failures(grading, RESTRICTED) == {"runAsNonRoot", "runAsUser",
                                             "capabilities_restricted"}
    assert failures(merging, RESTRICTED) == {"runAsNonRoot", "runAsUser"}


def test_kubernetes_grader_keeps_only_what_giving_a_program_its_own_uid_needs():
    grading, merging = k8s_jobs()
    pod = grading["spec"]["template"]["spec"]
    (grader,) = pod["containers"]
    assert grader["securityContext"] == {
        "runAsUser": 0, "allowPrivilegeEscalation": False,
        "capabilities": {"drop": ["ALL"], "add": ["SETUID", "SETGID", "CHOWN", "FOWNER",
                                                  "KILL"]}}
    for spec in (pod, merging["spec"]["template"]["spec"]):
        assert spec["securityContext"]["seccompProfile"] == {"type": "RuntimeDefault"}
        assert spec["automountServiceAccountToken"] is False  # no API token to students
        for container in spec.get("initContainers", []) + spec["containers"]:
            assert container["securityContext"]["capabilities"]["drop"] == ["ALL"]
            assert container["securityContext"]["allowPrivilegeEscalation"] is False


def mount_at(container: dict[str, Any], path: str) -> dict[str, Any]:
    """The volume mount a path in the container lies on: the deepest one above it."""
    above = [m for m in container["volumeMounts"]
             if path == m["mountPath"] or path.startswith(m["mountPath"].rstrip("/") + "/")]
    return max(above, key=lambda m: len(m["mountPath"]))


def test_kubernetes_grader_reads_submissions_read_only_and_writes_only_out():
    grading, _ = k8s_jobs()
    (grader,) = grading["spec"]["template"]["spec"]["containers"]
    script = grader["args"][0]
    assert "grade-batch timer_sync /data/submissions" in script
    assert "--csv /data/out/gradebook-" in script and "--out /data/out/reports" in script
    submissions = mount_at(grader, "/data/submissions/student01")
    assert submissions["name"] == "data" and submissions["readOnly"] is True
    out = mount_at(grader, "/data/out/reports")
    assert out["name"] == "data" and out["subPath"] == "out" and not out.get("readOnly")


def test_kubernetes_course_token_in_the_init_container_and_course_root_only():
    grading, merging = k8s_jobs()
    pod = grading["spec"]["template"]["spec"]
    secrets = {v["name"] for v in pod["volumes"] if "secret" in v}
    (sync,), (grader,) = pod["initContainers"], pod["containers"]
    assert secrets and secrets <= {m["name"] for m in sync["volumeMounts"]}
    assert not secrets & {m["name"] for m in grader["volumeMounts"]}
    script = grader["args"][0]
    assert script.startswith("chmod 0700 /course &&")  # before any student's program
    assert "course" not in {m["name"] for m in
                            merging["spec"]["template"]["spec"]["containers"][0]["volumeMounts"]}


def test_cli_prints_a_workflow():
    result = CliRunner().invoke(main, ["workflow", "k8s-shards", "--shards", "2"])
    assert result.exit_code == 0
    assert next(yaml.safe_load_all(result.output))["spec"]["completions"] == 2
