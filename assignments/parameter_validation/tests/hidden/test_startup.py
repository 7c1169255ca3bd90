"""Hidden tests: an invalid -p override stops the node with a clear error."""

import pytest

from autograder.core.errors import StudentFailure
from autograder.i18n import _

# Startup is a matter of the process, not of simulation time: wall seconds.
EXIT_WITHIN = 10.0


@pytest.mark.points(1)
def test_invalid_override_exits(start_node):
    """Started with an invalid override, the node exits non-zero naming the parameter"""
    for name, value in (("max_linear_speed", 3.0), ("max_angular_speed", -1.0)):
        node = start_node({name: value}, wait_for_node=False)
        code = node.wait_exit(EXIT_WITHIN)
        if code is None:
            node.stop()
            raise StudentFailure(
                _("Started with -p {name}:={value}, the node was still running after "
                  "{seconds:.0f} s.").format(name=name, value=value, seconds=EXIT_WITHIN),
                _("Check the starting values after declare_parameter; log an error and "
                  "exit with a non-zero status."))
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
