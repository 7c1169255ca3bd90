"""The threat model's table of attacks and machine shapes (docs/operators/security.md) is
this one, word for word, and every cell that says an attack is stopped names the test that
tries it in that shape (issues 28 and 29). Run with ``-s`` to see the table printed."""

from __future__ import annotations

import re
from pathlib import Path

TESTS = Path(__file__).resolve().parents[1]
PAGE = TESTS.parent / "docs" / "operators" / "security.md"

SHAPES = ("root with namespaces: strict", "root in a container: user",
          "root in a container without CAP_SETUID: basic", "an ordinary user: basic")

# attack, then for each shape: what happens, and the test that tries it there (None: the
# cell says it is not stopped, so there is nothing to prove). The container shapes and
# the ordinary user run the whole corpus in tests/sandbox/test_shapes.py; strict, in
# tests/sandbox/test_hostile.py.
Cell = tuple[str, "str | None"]
TABLE: list[tuple[str, Cell, Cell, Cell, Cell]] = [
    ("a module beside the node (`json.py`) run by the grader as root",
     ("never imported", "test_modules_beside_the_node_run_only_as_the_student"),
     ("never imported", "test_modules_beside_the_node_never_run_as_root"),
     ("never imported", "test_modules_beside_the_node_never_run_by_the_grader"),
     ("never imported", "test_the_launcher_never_imports_a_module_beside_the_node")),
    ("a link, device or FIFO in the submission",
     ("refused, exit 2", "test_what_the_grader_will_not_read_is_refused_by_name"),
     ("refused, exit 2", "test_what_the_grader_will_not_read_is_refused_by_name"),
     ("refused, exit 2", "test_what_the_grader_will_not_read_is_refused_by_name"),
     ("refused, exit 2", "test_the_cli_refuses_a_linked_submission_as_the_students_error")),
    ("reading hidden tests or solutions",
     ("covered by the mount namespace", "test_hidden_tests_and_solutions_are_out_of_reach"),
     ("closed by mode (0750)", "test_hidden_tests_and_solutions_stay_closed"),
     ("**not stopped**", None), ("**not stopped**", None)),
    ("reading another student's files in a batch",
     ("covered by the mount namespace", "test_classmates_are_out_of_reach"),
     ("closed by mode", "test_classmates_files_stay_closed"),
     ("**not stopped**", None), ("**not stopped**", None)),
    ("stopping, tracing or reading the memory of the grader (the report's key)",
     ("another user, and out of sight", "test_the_machines_processes_are_out_of_sight_and_reach"),
     ("another user", "test_the_graders_processes_cannot_be_stopped_or_traced"),
     ("memory and tracing closed (not dumpable); a stopped grading is the grader's failure",
      "test_a_stopped_grading_is_the_graders_failure_and_its_memory_closed"),
     ("memory and tracing closed (not dumpable); a stopped grading is the grader's failure",
      "test_a_stopped_grading_is_the_graders_failure_and_its_memory_closed")),
    ("a daemon that rewrites the results afterwards",
     ("ended with its user", "test_without_cgroups_a_daemon_still_ends_with_the_program"),
     ("ended with its user", "test_no_result_is_rewritten"),
     ("**not stopped** (no writable cgroup)", None),
     ("ended by its cgroup where one exists; **else not stopped**", None)),
    ("SysV IPC, POSIX queues, files in `/tmp` and `/dev/shm` left behind",
     ("its own namespaces, gone with it", "test_ipc_objects_and_scratch_files_go_with_the_program"),
     ("swept as its user", "test_scratch_files_are_swept"),
     ("**left**", None), ("**left** (they are the user's own)", None)),
    ("a fork bomb's unreaped children starving the next program of its user",
     ("waited for: the next starts with its whole budget",
      "test_the_next_program_of_a_user_is_not_starved_by_a_fork_bombs_zombies"),
     ("waited for: the next starts with its whole budget",
      "test_the_next_program_of_a_user_is_not_starved_by_a_fork_bombs_zombies"),
     ("**no budget at all** (root, no cgroup)", None),
     ("its budget is the user's tasks then and 128 more",
      "test_the_next_program_of_a_user_is_not_starved_by_a_fork_bombs_zombies")),
    ("output that clears the screen or fakes a score",
     ("shown as text", "test_output_that_lies_shows_as_text"),
     ("shown as text", "test_output_that_lies_shows_as_text"),
     ("shown as text", "test_output_that_lies_shows_as_text"),
     ("shown as text", "test_output_that_lies_shows_as_text")),
    ("publishing the world's topics, a second grader node, setting the grader's parameters",
     ("caught, or no such service", "test_tampering_is_caught_not_rewarded"),
     ("caught, or no such service", "test_tampering_with_the_world_is_caught"),
     ("caught, or no such service", "test_tampering_with_the_world_is_caught"),
     ("caught, or no such service", "test_tampering_with_the_world_is_caught")),
    ("joining another grading's ROS domain, or a stranger joining this one's",
     ("nobody to find: a network namespace each", "test_no_other_grading_is_in_reach"),
     ("its own grading fails; the other is disturbed, never blamed, and graded again",
      "test_joining_another_domain_fails_only_the_joiner"),
     ("**not told apart** (the student is the grader's user)", None),
     ("another user's: disturbed, never blamed; **the user's own not told apart**", None)),
    ("holding every domain's lock file and port",
     ("its own `/tmp` and network: nothing to hold", "test_no_other_grading_is_in_reach"),
     ("passed over: a student's user holds nothing",
      "test_hoarding_every_domain_blocks_no_classmate"),
     ("**blocks the other gradings**", None),
     ("**blocks other gradings while it runs**", None)),
    ("the network beyond loopback",
     ("none: a network namespace", "test_no_network_beyond_loopback"),
     ("**reachable**", None), ("**reachable**", None), ("**reachable**", None)),
    ("other processes' command lines",
     ("hidden (`/proc` with `hidepid`)", "test_the_machines_processes_are_out_of_sight_and_reach"),
     ("**visible**", None), ("**visible**", None), ("**visible**", None)),
    ("spinning children that slow other gradings",
     ("one CPU share (cpu cgroup)",
      "test_a_program_and_what_it_forks_share_one_cpu_group_of_their_own"),
     ("**not stopped** (no writable cgroup)", None),
     ("**not stopped** (no writable cgroup)", None),
     ("one CPU share where a cgroup is delegated",
      "test_a_program_and_what_it_forks_share_one_cpu_group_of_their_own")),
    ("the grade is official",
     ("yes", "test_runs_as_its_own_user_where_strict"),
     ("yes", "test_ends_with_a_score_a_message_and_the_shapes_label"),
     ("no: `official: false`, and the recipes refuse it",
      "test_ends_with_a_score_a_message_and_the_shapes_label"),
     ("no: `official: false`, and the recipes refuse it",
      "test_an_ordinary_user_grade_is_labelled_and_recipes_refuse_it")),
]


def render() -> str:
    """The table as the security page holds it."""
    lines = [f"| attack | {' | '.join(SHAPES)} |", "|---" * (len(SHAPES) + 1) + "|"]
    for attack, *cells in TABLE:
        lines.append(f"| {attack} | {' | '.join(text for text, _proof in cells)} |")
    return "\n".join(lines)


def _test_names() -> set[str]:
    names: set[str] = set()
    for path in TESTS.rglob("test_*.py"):  # the project's tests, not the exercises'
        if {"fixtures", "submissions"} & set(path.relative_to(TESTS).parts):
            continue
        names |= set(re.findall(r"^def (test_\w+)", path.read_text(encoding="utf-8"), re.M))
    return names


def test_the_security_page_holds_this_table():
    print("\n" + render())
    assert render() in PAGE.read_text(encoding="utf-8")


def test_every_stopped_attack_names_a_test_that_exists():
    known = _test_names()
    for attack, *cells in TABLE:
        for shape, (text, proof) in zip(SHAPES, cells, strict=True):
            stopped = "not stopped" not in text and "**" not in text
            assert proof is not None or not stopped, (attack, shape)
            assert proof is None or proof in known, (attack, shape, proof)
