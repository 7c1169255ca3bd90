"""``python -m sim``: the same commands as ``autograder sim``."""

import os

from content.i18n import set_language
from sim.cli import sim_cli

if __name__ == "__main__":
    # The language the platform prints in (README, Settings); `autograder` reads it too.
    set_language(os.environ.get("AUTOGRADER_LANG") or "en")
    sim_cli(prog_name="python -m sim")
