"""The error-message assertion the loader tests share."""
from __future__ import annotations

import re

import pytest

from vampc.errors import VampcError


def assert_error(call, path, message: str) -> None:
    """`call` raises a VampcError whose whole message is 'PATH: <message>' on one line."""
    with pytest.raises(VampcError) as info:
        call()
    text = str(info.value)
    assert "\n" not in text
    assert re.fullmatch(re.escape(str(path)) + ": " + message, text), text
