"""The tests' Pod Security Standards checker (tests/pod_security.py) fails what the standard
forbids: each known-bad pod below fails exactly the check the standard names for it, and
is otherwise a pod the Kubernetes API schema accepts, so the failure is the policy's."""

import copy
from collections.abc import Callable
from typing import Any

import kubernetes_validate
import pytest
from pod_security import BASELINE, RESTRICTED, failures

K8S_VERSION = "1.30"


def restricted_pod() -> dict[str, Any]:
    """A pod that meets restricted (and so baseline)."""
    return {
        "apiVersion": "v1", "kind": "Pod", "metadata": {"name": "p"},
        "spec": {
            "securityContext": {"runAsNonRoot": True,
                                "seccompProfile": {"type": "RuntimeDefault"}},
            "initContainers": [{"name": "init", "image": "busybox", "securityContext": {
                "allowPrivilegeEscalation": False, "capabilities": {"drop": ["ALL"]}}}],
            "containers": [{"name": "main", "image": "busybox", "securityContext": {
                "allowPrivilegeEscalation": False, "capabilities": {"drop": ["ALL"]}}}],
            "volumes": [{"name": "scratch", "emptyDir": {}}],
        },
    }


Change = Callable[[dict[str, Any]], None]


def main(pod: dict[str, Any]) -> dict[str, Any]:
    return pod["spec"]["containers"][0]


def context(container: dict[str, Any]) -> dict[str, Any]:
    return container["securityContext"]


# Each breaks one control of baseline (and so of restricted).
BASELINE_BREAKS: dict[str, tuple[Change, str]] = {
    "privileged": (lambda p: context(main(p)).update(privileged=True), "privileged"),
    "privileged init container": (
        lambda p: context(p["spec"]["initContainers"][0]).update(privileged=True),
        "privileged"),
    "hostNetwork": (lambda p: p["spec"].update(hostNetwork=True), "hostNamespaces"),
    "hostPID": (lambda p: p["spec"].update(hostPID=True), "hostNamespaces"),
    "hostIPC": (lambda p: p["spec"].update(hostIPC=True), "hostNamespaces"),
    "hostPath": (lambda p: p["spec"]["volumes"].append(
        {"name": "host", "hostPath": {"path": "/"}}), "hostPathVolumes"),
    "adds SYS_ADMIN": (lambda p: context(main(p))["capabilities"].update(add=["SYS_ADMIN"]),
                       "capabilities_baseline"),
    "adds NET_RAW": (lambda p: context(main(p))["capabilities"].update(add=["NET_RAW"]),
                     "capabilities_baseline"),
    "hostPort": (lambda p: main(p).update(ports=[{"containerPort": 80, "hostPort": 8080}]),
                 "hostPorts"),
    "probe on the host": (lambda p: main(p).update(livenessProbe={
        "httpGet": {"host": "10.0.0.1", "path": "/", "port": 80}}),
        "hostProbesAndHostLifecycle"),
    "seccomp Unconfined": (lambda p: context(main(p)).update(
        seccompProfile={"type": "Unconfined"}), "seccompProfile_baseline"),
    "unmasked /proc": (lambda p: context(main(p)).update(procMount="Unmasked"), "procMount"),
    "unsafe sysctl": (lambda p: p["spec"]["securityContext"].update(
        sysctls=[{"name": "kernel.msgmax", "value": "65536"}]), "sysctls"),
    "SELinux user": (lambda p: context(main(p)).update(seLinuxOptions={"user": "system_u"}),
                     "seLinuxOptions"),
    "SELinux type spc_t": (lambda p: context(main(p)).update(seLinuxOptions={"type": "spc_t"}),
                           "seLinuxOptions"),
    "AppArmor Unconfined": (lambda p: context(main(p)).update(
        appArmorProfile={"type": "Unconfined"}), "appArmorProfile"),
    "AppArmor annotation": (lambda p: p["metadata"].update(annotations={
        "container.apparmor.security.beta.kubernetes.io/main": "unconfined"}),
        "appArmorProfile"),
    "Windows HostProcess": (lambda p: context(main(p)).update(
        windowsOptions={"hostProcess": True}), "windowsHostProcess"),
}

# Each meets baseline but breaks one control of restricted.
RESTRICTED_BREAKS: dict[str, tuple[Change, str]] = {
    "privilege escalation": (lambda p: context(main(p)).pop("allowPrivilegeEscalation"),
                             "allowPrivilegeEscalation"),
    "runAsNonRoot unset": (lambda p: p["spec"]["securityContext"].pop("runAsNonRoot"),
                           "runAsNonRoot"),
    "a container runAsNonRoot false": (lambda p: context(main(p)).update(runAsNonRoot=False),
                                       "runAsNonRoot"),
    "runAsUser 0": (lambda p: context(main(p)).update(runAsUser=0), "runAsUser"),
    "seccomp unset": (lambda p: p["spec"]["securityContext"].pop("seccompProfile"),
                      "seccompProfile_restricted"),
    "keeps capabilities": (lambda p: context(main(p)).pop("capabilities"),
                           "capabilities_restricted"),
    "adds SETUID": (lambda p: context(main(p))["capabilities"].update(add=["SETUID"]),
                    "capabilities_restricted"),
    "nfs volume": (lambda p: p["spec"]["volumes"].append(
        {"name": "share", "nfs": {"server": "nfs.invalid", "path": "/"}}), "restrictedVolumes"),
}


def broken(change: Change) -> dict[str, Any]:
    pod = restricted_pod()
    change(pod)
    kubernetes_validate.validate(pod, K8S_VERSION, strict=True)  # a pod the API would take
    return pod


def test_a_restricted_pod_meets_both_levels():
    pod = restricted_pod()
    kubernetes_validate.validate(pod, K8S_VERSION, strict=True)
    assert failures(pod, BASELINE) == failures(pod, RESTRICTED) == set()


@pytest.mark.parametrize("change,check", BASELINE_BREAKS.values(), ids=BASELINE_BREAKS)
def test_each_baseline_break_fails_its_check(change: Change, check: str):
    assert failures(broken(change), BASELINE) == {check}
    assert failures(broken(change), RESTRICTED)


@pytest.mark.parametrize("change,check", RESTRICTED_BREAKS.values(), ids=RESTRICTED_BREAKS)
def test_each_restricted_break_fails_only_restricted(change: Change, check: str):
    pod = broken(change)
    assert failures(pod, BASELINE) == set()
    assert failures(pod, RESTRICTED) == {check}


def test_a_default_pod_is_baseline_and_fails_restricted_for_the_four_known_reasons():
    """What ``kubectl run`` makes: the four warnings Kubernetes prints for it at restricted."""
    pod = {"apiVersion": "v1", "kind": "Pod", "metadata": {"name": "p"},
           "spec": {"containers": [{"name": "main", "image": "busybox"}]}}
    assert failures(pod, BASELINE) == set()
    assert failures(pod, RESTRICTED) == {"allowPrivilegeEscalation", "runAsNonRoot",
                                         "seccompProfile_restricted", "capabilities_restricted"}


def test_a_jobs_pod_template_is_what_is_checked():
    pod = broken(BASELINE_BREAKS["privileged"][0])
    job = {"apiVersion": "batch/v1", "kind": "Job", "metadata": {"name": "j"},
           "spec": {"template": {"metadata": {}, "spec": copy.deepcopy(pod["spec"])}}}
    job["spec"]["template"]["spec"]["restartPolicy"] = "Never"
    kubernetes_validate.validate(job, K8S_VERSION, strict=True)
    assert failures(job, BASELINE) == {"privileged"}


def test_the_schema_check_catches_a_misspelt_field():
    pod = restricted_pod()
    main(pod)["securityContex"] = main(pod).pop("securityContext")
    with pytest.raises(kubernetes_validate.ValidationError):
        kubernetes_validate.validate(pod, K8S_VERSION, strict=True)
