"""Fixtures more than one test module uses."""

import pvlib
import pytest


@pytest.fixture
def spa_calls(monkeypatch):
    """A list that grows by one at every call of pvlib's SPA (which still answers)."""
    calls = []
    original = pvlib.solarposition.spa_python
    monkeypatch.setattr(pvlib.solarposition, "spa_python", lambda *a, **k: calls.append(1) or original(*a, **k))
    return calls
