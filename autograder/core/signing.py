"""The grading report is signed: a student who can write the grader's files (basic
isolation runs them as the same user) cannot forge a score.

The key comes to the pytest child over a pipe, never through the environment, which a
process of the same user could read in ``/proc``.
"""

from __future__ import annotations

import hashlib
import hmac
import json
from typing import Any


class Forged(Exception):
    """The report's signature does not match: someone else wrote it."""


def sign(payload: str, key: bytes) -> str:
    digest = hmac.new(key, payload.encode(), hashlib.sha256).hexdigest()
    return json.dumps({"payload": payload, "hmac": digest})


def verify(text: str, key: bytes) -> dict[str, Any]:
    """The signed payload, or :class:`Forged`; an unreadable file is Forged too."""
    try:
        wrapper = json.loads(text)
        payload, digest = wrapper["payload"], wrapper["hmac"]
    except (ValueError, KeyError, TypeError):
        raise Forged from None
    expected = hmac.new(key, payload.encode(), hashlib.sha256).hexdigest()
    if not isinstance(digest, str) or not hmac.compare_digest(digest, expected):
        raise Forged
    return json.loads(payload)
