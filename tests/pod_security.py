"""The Pod Security Standards' baseline and restricted levels, checked on a manifest's pod
(a Pod, or the pod template of a Job, CronJob or other workload), for the tests: which of
the standard's checks it fails.

No package on PyPI checks the standard itself: k8s-policy-guard, the one that says it does,
fails capabilities that baseline allows (SETUID, KILL, ...). So this module writes the
rules down from the Kubernetes project's own admission plugin, k8s.io/pod-security-admission
(``policy/check_*.go``, whose comments are the standard's table). Each check carries that
plugin's check ID and the control's name in the standard, at the newest policy version
(1.37). Two simplifications, both stricter than the standard, never laxer: a pod with
``hostUsers: false`` gets no user-namespace relaxation, and a Windows pod no exemption.
Seccomp's annotations, which the plugin stopped reading at 1.19, are not read either.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

Spec = dict[str, Any]

BASELINE = "baseline"
RESTRICTED = "restricted"

# Baseline's "Capabilities": the container runtime's default set.
BASELINE_CAPABILITIES = frozenset({
    "AUDIT_WRITE", "CHOWN", "DAC_OVERRIDE", "FOWNER", "FSETID", "KILL", "MKNOD",
    "NET_BIND_SERVICE", "SETFCAP", "SETGID", "SETPCAP", "SETUID", "SYS_CHROOT"})
# Baseline's "Sysctls": the safe ones, namespaced per pod.
SAFE_SYSCTLS = frozenset({
    "kernel.shm_rmid_forced", "net.ipv4.ip_local_port_range", "net.ipv4.tcp_syncookies",
    "net.ipv4.ping_group_range", "net.ipv4.ip_unprivileged_port_start",
    "net.ipv4.ip_local_reserved_ports", "net.ipv4.tcp_keepalive_time",
    "net.ipv4.tcp_fin_timeout", "net.ipv4.tcp_keepalive_intvl",
    "net.ipv4.tcp_keepalive_probes", "net.ipv4.tcp_rmem", "net.ipv4.tcp_wmem",
    "net.ipv4.tcp_slow_start_after_idle", "net.ipv4.tcp_notsent_lowat"})
SELINUX_TYPES = frozenset({"", "container_t", "container_init_t", "container_kvm_t",
                           "container_engine_t"})
PROFILE_TYPES = frozenset({"RuntimeDefault", "Localhost"})  # seccomp and AppArmor
# Restricted's "Volume Types": the inline volume sources it allows.
RESTRICTED_VOLUMES = frozenset({"configMap", "csi", "downwardAPI", "emptyDir", "ephemeral",
                                "image", "persistentVolumeClaim", "projected", "secret"})
APPARMOR_ANNOTATION = "container.apparmor.security.beta.kubernetes.io/"


def pod_of(manifest: Spec) -> tuple[Spec, Spec]:
    """The pod's metadata and spec: the manifest's own for a Pod, else its pod template's."""
    kind = manifest["kind"]
    if kind == "Pod":
        return manifest.get("metadata") or {}, manifest["spec"]
    spec = manifest["spec"]
    if kind == "CronJob":
        spec = spec["jobTemplate"]["spec"]
    template = spec["template"]
    return template.get("metadata") or {}, template["spec"]


def containers(spec: Spec) -> Iterator[Spec]:
    """Every container the checks look at: init, regular and ephemeral."""
    for field in ("initContainers", "containers", "ephemeralContainers"):
        yield from spec.get(field) or []


def _context(item: Spec) -> Spec:
    return item.get("securityContext") or {}


def _pod_and_containers(spec: Spec) -> Iterator[Spec]:
    """The pod's security context, then each container's."""
    yield _context(spec)
    for container in containers(spec):
        yield _context(container)


# --- baseline ----------------------------------------------------------------------------

def _windows_host_process(meta: Spec, spec: Spec) -> bool:
    """HostProcess: no ``windowsOptions.hostProcess: true``, pod or container."""
    return not any((c.get("windowsOptions") or {}).get("hostProcess") is True
                   for c in _pod_and_containers(spec))


def _host_namespaces(meta: Spec, spec: Spec) -> bool:
    """Host Namespaces: no hostNetwork, hostPID or hostIPC."""
    return not any(spec.get(f) is True for f in ("hostNetwork", "hostPID", "hostIPC"))


def _privileged(meta: Spec, spec: Spec) -> bool:
    """Privileged Containers: no ``privileged: true``."""
    return not any(_context(c).get("privileged") is True for c in containers(spec))


def _capabilities_baseline(meta: Spec, spec: Spec) -> bool:
    """Capabilities: none added beyond the runtime's default set."""
    return all(set((_context(c).get("capabilities") or {}).get("add") or [])
               <= BASELINE_CAPABILITIES for c in containers(spec))


def _host_path_volumes(meta: Spec, spec: Spec) -> bool:
    """HostPath Volumes: none."""
    return not any("hostPath" in v for v in spec.get("volumes") or [])


def _host_ports(meta: Spec, spec: Spec) -> bool:
    """Host Ports: none (0 or unset)."""
    return not any(port.get("hostPort") for c in containers(spec)
                   for port in c.get("ports") or [])


def _host_probes_and_lifecycle(meta: Spec, spec: Spec) -> bool:
    """Host Probes / Lifecycle Hooks: no ``host`` in an httpGet or tcpSocket handler."""
    for c in containers(spec):
        handlers = [c.get(p) or {} for p in ("livenessProbe", "readinessProbe", "startupProbe")]
        handlers += [h or {} for h in (c.get("lifecycle") or {}).values()]
        if any((h.get(kind) or {}).get("host") for h in handlers
               for kind in ("httpGet", "tcpSocket")):
            return False
    return True


def _app_armor_profile(meta: Spec, spec: Spec) -> bool:
    """AppArmor: only RuntimeDefault or Localhost profiles (fields and old annotations)."""
    if any(c.get("appArmorProfile") and c["appArmorProfile"].get("type") not in PROFILE_TYPES
           for c in _pod_and_containers(spec)):
        return False
    return all(value in ("", "runtime/default") or value.startswith("localhost/")
               for key, value in (meta.get("annotations") or {}).items()
               if key.startswith(APPARMOR_ANNOTATION))


def _se_linux_options(meta: Spec, spec: Spec) -> bool:
    """SELinux: only the container types; no user or role."""
    for c in _pod_and_containers(spec):
        options = c.get("seLinuxOptions")
        if options and (options.get("type", "") not in SELINUX_TYPES
                        or options.get("user") or options.get("role")):
            return False
    return True


def _proc_mount(meta: Spec, spec: Spec) -> bool:
    """/proc Mount Type: the default masks (``procMount`` unset or Default)."""
    return all(_context(c).get("procMount", "Default") == "Default" for c in containers(spec))


def _seccomp_profile_baseline(meta: Spec, spec: Spec) -> bool:
    """Seccomp: where a profile is set, RuntimeDefault or Localhost (never Unconfined)."""
    return all(c["seccompProfile"].get("type") in PROFILE_TYPES
               for c in _pod_and_containers(spec) if c.get("seccompProfile"))


def _sysctls(meta: Spec, spec: Spec) -> bool:
    """Sysctls: only the safe set."""
    return all(s.get("name") in SAFE_SYSCTLS for s in _context(spec).get("sysctls") or [])


# --- restricted --------------------------------------------------------------------------

def _restricted_volumes(meta: Spec, spec: Spec) -> bool:
    """Volume Types: only configMap, csi, downwardAPI, emptyDir, ephemeral, image,
    persistentVolumeClaim, projected and secret."""
    return all(set(v) - {"name"} <= RESTRICTED_VOLUMES for v in spec.get("volumes") or [])


def _allow_privilege_escalation(meta: Spec, spec: Spec) -> bool:
    """Privilege Escalation: every container sets ``allowPrivilegeEscalation: false``."""
    return all(_context(c).get("allowPrivilegeEscalation") is False for c in containers(spec))


def _set_at_pod_or_each_container(spec: Spec, good: Callable[[Spec], bool | None]) -> bool:
    """A rule that the pod may state for all its containers: ``good`` is True (allowed),
    False (forbidden) or None (unset) for a security context. Passes when nothing is
    forbidden and every container is allowed by itself or by the pod."""
    pod = good(_context(spec))
    if pod is False:
        return False
    for container in containers(spec):
        mine = good(_context(container))
        if mine is False or (mine is None and not pod):
            return False
    return True


def _run_as_non_root(meta: Spec, spec: Spec) -> bool:
    """Running as Non-root: ``runAsNonRoot: true``, on the pod or on every container."""
    return _set_at_pod_or_each_container(spec, lambda c: c.get("runAsNonRoot"))


def _run_as_user(meta: Spec, spec: Spec) -> bool:
    """Running as Non-root user: no ``runAsUser: 0``, pod or container."""
    return not any(c.get("runAsUser") == 0 for c in _pod_and_containers(spec))


def _seccomp_profile_restricted(meta: Spec, spec: Spec) -> bool:
    """Seccomp: RuntimeDefault or Localhost, set on the pod or on every container."""
    def good(context: Spec) -> bool | None:
        profile = context.get("seccompProfile")
        return None if not profile else profile.get("type") in PROFILE_TYPES
    return _set_at_pod_or_each_container(spec, good)


def _capabilities_restricted(meta: Spec, spec: Spec) -> bool:
    """Capabilities: every container drops ALL and adds at most NET_BIND_SERVICE."""
    for c in containers(spec):
        caps = _context(c).get("capabilities") or {}
        if "ALL" not in (caps.get("drop") or []) or \
                set(caps.get("add") or []) - {"NET_BIND_SERVICE"}:
            return False
    return True


Check = Callable[[Spec, Spec], bool]
CHECKS: dict[str, dict[str, Check]] = {
    BASELINE: {
        "windowsHostProcess": _windows_host_process,
        "hostNamespaces": _host_namespaces,
        "privileged": _privileged,
        "capabilities_baseline": _capabilities_baseline,
        "hostPathVolumes": _host_path_volumes,
        "hostPorts": _host_ports,
        "hostProbesAndHostLifecycle": _host_probes_and_lifecycle,
        "appArmorProfile": _app_armor_profile,
        "seLinuxOptions": _se_linux_options,
        "procMount": _proc_mount,
        "seccompProfile_baseline": _seccomp_profile_baseline,
        "sysctls": _sysctls,
    },
    RESTRICTED: {
        "restrictedVolumes": _restricted_volumes,
        "allowPrivilegeEscalation": _allow_privilege_escalation,
        "runAsNonRoot": _run_as_non_root,
        "runAsUser": _run_as_user,
        "seccompProfile_restricted": _seccomp_profile_restricted,
        "capabilities_restricted": _capabilities_restricted,
        "procMount_restricted": _proc_mount,
    },
}
# A restricted check that replaces a baseline one at the restricted level (the plugin's
# OverrideCheckIDs): it says the same thing, more strictly.
OVERRIDES = {"restrictedVolumes": "hostPathVolumes", "capabilities_restricted":
             "capabilities_baseline", "seccompProfile_restricted": "seccompProfile_baseline",
             "procMount_restricted": "procMount"}


def failures(manifest: Spec, level: str) -> set[str]:
    """The IDs of the checks of ``level`` (baseline, or restricted with baseline's) that the
    manifest's pod fails; empty when the pod meets the level."""
    checks = dict(CHECKS[BASELINE])
    if level == RESTRICTED:
        checks.update(CHECKS[RESTRICTED])
        for replaced in OVERRIDES.values():
            checks.pop(replaced)
    elif level != BASELINE:
        raise ValueError(f"no Pod Security level {level!r}")
    meta, spec = pod_of(manifest)
    return {name for name, check in checks.items() if not check(meta, spec)}
