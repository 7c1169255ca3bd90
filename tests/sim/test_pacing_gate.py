"""A gated pacer (a grading's world) sends no tick until its gate opens: sim time stays at
its start however long a module takes to set up."""

import threading

from sim.pacing import Pacer


def _next_tick_in_thread(pacer: Pacer) -> tuple[threading.Thread, list]:
    got: list = []

    def run() -> None:
        with pacer.condition:
            got.append(pacer.next_tick())

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    return thread, got


def test_a_gated_pacer_plans_no_tick_until_the_gate_opens():
    pacer = Pacer(0.01, 1.0, gated=True)
    thread, got = _next_tick_in_thread(pacer)
    thread.join(0.2)
    assert thread.is_alive() and not got and pacer.gated
    pacer.open_gate()
    thread.join(2.0)
    assert got and got[0] is not None and not pacer.gated


def test_a_hold_inside_a_closed_gate_does_not_open_it():
    pacer = Pacer(0.01, 1.0, gated=True)
    with pacer.held():
        pass
    thread, got = _next_tick_in_thread(pacer)
    thread.join(0.2)
    assert thread.is_alive() and not got
    pacer.open_gate()
    thread.join(2.0)
    assert got


def test_an_open_gate_inside_a_hold_lets_ticks_go_when_the_hold_ends():
    pacer = Pacer(0.01, 1.0, gated=True)
    with pacer.held():
        pacer.open_gate()  # the start-up's wait for the node opens it, sim time still held
        thread, got = _next_tick_in_thread(pacer)
        thread.join(0.2)
        assert thread.is_alive() and not got
    thread.join(2.0)
    assert got


def test_stopping_a_gated_pacer_ends_its_wait():
    pacer = Pacer(0.01, 1.0, gated=True)
    thread, got = _next_tick_in_thread(pacer)
    pacer.stop()
    thread.join(2.0)
    assert got == [None]
