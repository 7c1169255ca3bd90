"""The machine shapes the grader meets, as command prefixes a test runs the grader under
(issue 29): root in a container without namespaces (Docker's capabilities, Gradescope; a
pod's five), the same without CAP_SETUID (where the grader falls to basic isolation as
root), and an ordinary user."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

NOBODY = 65534
# Docker's default capabilities (Gradescope's container), and the five a Kubernetes pod of
# ours keeps (autograder/templates/ci/k8s-shards.yml): neither has CAP_SYS_ADMIN.
DOCKER_CAPS = ("chown", "dac_override", "fowner", "fsetid", "kill", "setgid", "setuid",
               "setpcap", "net_bind_service", "net_raw", "sys_chroot", "mknod", "audit_write",
               "setfcap")
POD_CAPS = ("setuid", "setgid", "chown", "fowner", "kill")
# A container whose root cannot change user: the grader's only choice is basic isolation.
NO_SETUID_CAPS = tuple(cap for cap in DOCKER_CAPS if cap not in ("setuid", "setgid"))


def container(caps: tuple[str, ...], own_pids: bool = False) -> list[str]:
    """A command prefix: a container's root with only ``caps``, and a read-only empty
    cgroup filesystem, as the issue gives the shape. ``own_pids``: a PID namespace of its
    own too (as Docker and Kubernetes give), whose end ends every process left in it."""
    bounding = ",".join(["-all", *(f"+{cap}" for cap in caps)])
    pids = ["--pid", "--fork", "--mount-proc"] if own_pids else []
    return ["unshare", "--mount", *pids, "--propagation", "private", "sh", "-c",
            "mount -t tmpfs -o ro,size=4k tmpfs /sys/fs/cgroup && "
            f'exec setpriv --bounding-set={bounding} --inh-caps=-all "$@"', "container"]


def ordinary_user(uid: int = NOBODY) -> list[str]:
    """A command prefix: an ordinary user (in a PID namespace of the test's, whose end
    ends what basic isolation leaves running)."""
    return ["unshare", "--mount", "--pid", "--fork", "--mount-proc", "--propagation",
            "private", "setpriv", f"--reuid={uid}", f"--regid={uid}", "--clear-groups"]


def world_readable_folder(prefix: str) -> Path:
    """A folder every user can pass through, as /autograder is (pytest's are 0700)."""
    folder = Path(tempfile.mkdtemp(prefix=prefix))
    folder.chmod(0o755)
    return folder


def clean_env(path: str) -> dict[str, str]:
    """The environment a container starts with: none of this venv's or this course's."""
    keep = ("HOME", "LANG", "LC_ALL", "TZ", "TMPDIR")
    return {**{k: v for k, v in os.environ.items() if k in keep}, "PATH": path}
