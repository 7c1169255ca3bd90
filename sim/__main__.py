"""``python -m sim``: the same commands as ``autograder sim``."""

from sim.cli import sim_cli

if __name__ == "__main__":
    sim_cli(prog_name="python -m sim")
