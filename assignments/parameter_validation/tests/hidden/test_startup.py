"""Hidden tests: an invalid -p override stops the node with a clear error."""

import pytest
from helpers import RANGES

from autograder.core.errors import StudentFailure
from autograder.i18n import _

# Startup is a matter of the process, not of simulation time: wall seconds.
EXIT_WITHIN = 10.0
# Invalid overrides, each past another bound: above one limit's range, below the other's.
OVERRIDES = (("max_linear_speed", 3.0), ("max_angular_speed", -1.0))
NODE = "velocity_governor"
VALID = ("max_linear_speed", 0.8)  # within its range: the node must run with it


@pytest.mark.points(1)
def test_invalid_override_exits(start_node, probe):
    """A valid -p override runs; an invalid one exits non-zero, the log naming the parameter"""
    _reads_a_valid_override(start_node, probe)
    # Overrides the node did refuse, naming them: proof that its startup check exists.
    refused_before: list[tuple[str, float]] = []
    for i, (name, value) in enumerate(OVERRIDES):
        node = start_node({name: value}, wait_for_node=False)
        code = node.wait_exit(EXIT_WITHIN)
        if code is None:
            node.stop()
            # What it refuses after this one tells a missing bound from a missing check.
            later = [(n, v) for n, v in OVERRIDES[i + 1:] if _refuses(start_node, n, v)]
            raise StudentFailure(
                _("Started with -p {name}:={value}, the node was still running after "
                  "{seconds:.0f} s.").format(name=name, value=value, seconds=EXIT_WITHIN),
                _still_running_hint(name, value, refused_before + later))
        if code == 0:
            raise StudentFailure(
                _("Started with -p {name}:={value}, the node exited with status 0; a refusal "
                  "must exit non-zero.").format(name=name, value=value),
                _("Return 1 from `main()` and call `sys.exit(main())`."))
        if name not in node.output():
            raise StudentFailure(
                _("Started with -p {name}:={value}, the node exited but its log does not name "
                  "{name}. Its last lines:\n{tail}").format(
                    name=name, value=value, tail=node.output_tail(8)),
                _("Log the problem with `self.get_logger().error(...)`, naming the parameter."))
        refused_before.append((name, value))


def _reads_a_valid_override(start_node, probe) -> None:
    """The same program, started with a valid override, comes up and holds that value: its
    exits below are then refusals of a value it read, not a crash that happens to print a
    parameter's name."""
    name, value = VALID
    try:
        node = start_node({name: value})
    except StudentFailure as failure:
        raise StudentFailure(
            _("Started with a valid override, -p {name}:={value}, the node did not come up, "
              "so an exit with an invalid one would show nothing:\n{why}").format(
                name=name, value=value, why=failure.message), failure.hint) from None
    try:
        held = probe.get_parameters(NODE, [name])[name]
    finally:
        node.stop()
    if held != value:
        raise StudentFailure(
            _("Started with -p {name}:={value}, the node came up but reads {name}={held!r}, "
              "so an exit with an invalid value would not be a refusal of it.").format(
                name=name, value=value, held=held),
            _("Declare {name} with `self.declare_parameter('{name}', 0.5)`: the -p override "
              "then becomes its value.").format(name=name))


def _refuses(start_node, name: str, value: float) -> bool:
    """Whether the node, started with ``-p name:=value``, exits non-zero naming ``name``."""
    node = start_node({name: value}, wait_for_node=False)
    code = node.wait_exit(EXIT_WITHIN)
    if code is None:
        node.stop()
    return code not in (None, 0) and name in node.output()


def _still_running_hint(name: str, value: float,
                        refused: list[tuple[str, float]]) -> str:
    """The fix for a node that ran on with an invalid override, by what it did refuse."""
    if refused:
        low, high = RANGES[name]
        other, other_value = refused[0]
        if value < low:
            text = _("Started with -p {other}:={other_value} it did exit, so the starting "
                     "values are checked, but `{name}={value}` got through: check the lower "
                     "bound there too (`{name} >= {low}`).")
        else:
            text = _("Started with -p {other}:={other_value} it did exit, so the starting "
                     "values are checked, but `{name}={value}` got through: check the upper "
                     "bound there too (`{name} <= {high}`).")
        return text.format(other=other, other_value=other_value, name=name, value=value,
                           low=low, high=high)
    return _("declare_parameter applies the -p overrides before any on-set callback exists, "
             "so your callback never saw `{name}={value}`. After declaring, check the "
             "starting values yourself, log an error naming {name} and return 1 from "
             "`main()`, ending the file with `sys.exit(main())`.").format(name=name, value=value)
