"""Hostile: named like the standard library's ctypes; says who imported it, then gets out of
the way so whoever imported it goes on with the real module."""
import os
import sys

print("SHADOW ctypes IMPORTED AS UID", os.getuid(), flush=True)
if os.getuid() == 0:
    print("ROOT CODE RAN", flush=True)
here = os.path.dirname(os.path.abspath(__file__))
sys.path[:] = [p for p in sys.path if os.path.abspath(p or ".") != here]
del sys.modules[__name__]
import ctypes as _real  # noqa: E402

sys.modules[__name__] = _real
