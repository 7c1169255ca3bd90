"""When a wait counts as stalled, and whose failure a stalled wait is: the program's if
it (its node, or any process it started) kept the CPU busy, else the machine's."""

from autograder.plugin.probe import kept_busy, stall_cap


def test_a_busy_loop_is_blamed_even_on_a_loaded_machine():
    # 10 s of wall time: running 4 s, waiting for a CPU the other 6 (never asleep).
    assert kept_busy(4.0, 6.0, 10.0)


def test_a_busy_loop_given_a_small_share_of_a_crowded_machine_is_blamed():
    # 12 s of wall time at load 12 on two cores: running 2 s, queued the other 10.
    assert kept_busy(2.0, 10.0, 12.0)


def test_an_idle_node_on_a_starved_machine_is_not_blamed():
    # It ran 0.3 s and waited 2 s: the rest of the 10 s it slept, waiting for ticks.
    assert not kept_busy(0.3, 2.0, 10.0)


def test_a_node_kept_waiting_all_along_is_not_blamed():
    # Four threads queued for a CPU for 9 s each, 0.3 s of CPU between them: waits add up
    # past the wall time, and what ran is below BUSY_CPU_SECONDS.
    assert not kept_busy(0.3, 36.0, 10.0)


def test_children_spinning_to_starve_the_world_are_the_programs_doing():
    # An idle node and 100 children that spin on 2 cores for 10 s: the family ran about
    # 19 s and queued about 980 s between them.
    assert kept_busy(19.0, 980.0, 10.0)


def test_nothing_watched_is_never_the_node():
    assert not kept_busy(0.0, 0.0, 12.0)


# How long a wait may take before it counts as stalled.

def test_a_wait_at_real_time_or_faster_is_given_four_times_its_sim_time():
    assert stall_cap(3.0, 1.0) == stall_cap(3.0, 4.0) == stall_cap(3.0, 0.0) == 12.0


def test_a_wait_below_real_time_is_given_four_times_what_its_pace_takes():
    """At half pace a 3 s wait takes 6 s before any hold: a cap of 12 s left a loaded
    machine's holds only 6 s, and the callback_groups proof met a grader error there."""
    assert stall_cap(3.0, 0.5) == 4 * 3.0 / 0.5
    assert stall_cap(1.0, 0.05) == 4 * 1.0 / 0.05


def test_a_short_wait_is_given_at_least_ten_seconds():
    assert stall_cap(0.5, 1.0) == stall_cap(0.5, 0.5) == 10.0
