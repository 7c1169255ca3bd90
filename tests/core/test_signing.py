"""The signed grading report (autograder.core.signing): what the key signed reads back,
anything else is Forged."""

from __future__ import annotations

import json

import pytest

from autograder.core.signing import Forged, sign, verify

KEY = b"k" * 32


def test_a_signed_payload_reads_back() -> None:
    payload = json.dumps({"tests": [{"name": "t", "status": "passed"}], "score": "1"})
    assert verify(sign(payload, KEY), KEY) == json.loads(payload)


@pytest.mark.parametrize("tamper", [
    lambda text: text.replace('\\"passed\\"', '\\"failed\\"'),  # the payload changed
    lambda text: json.dumps({**json.loads(text), "hmac": "0" * 64}),  # the digest changed
    lambda text: json.dumps({"payload": json.loads(text)["payload"]}),  # no digest
    lambda text: json.dumps({**json.loads(text), "hmac": 7}),  # not a digest
    lambda text: text[:-5],  # cut short: not JSON
    lambda text: "[]",  # JSON of another shape
], ids=["payload", "digest", "no-digest", "digest-type", "truncated", "shape"])
def test_a_changed_report_is_forged(tamper) -> None:
    text = sign(json.dumps({"status": "passed"}), KEY)
    with pytest.raises(Forged):
        verify(tamper(text), KEY)


def test_another_key_is_forged() -> None:
    text = sign("{}", KEY)
    with pytest.raises(Forged):
        verify(text, b"another key")
    assert verify(sign("{}", b""), b"") == {}  # the empty key signs too, only for itself
