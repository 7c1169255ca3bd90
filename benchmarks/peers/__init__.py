"""The world against its peers on one shared scenario (``benchmarks/bench_peers.py``).

One module per simulator, each with ``NAME``, ``PACKAGE`` (what ``pip`` installs) and
``run(scenario) -> Run``; a peer whose package is missing is reported, not run.
"""
