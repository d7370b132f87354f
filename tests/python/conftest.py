"""Fixtures shared by the Python tests."""
import tempfile

import pytest


@pytest.fixture(scope="module")
def work():
    """A temporary folder for one test module's files, removed after it."""
    with tempfile.TemporaryDirectory() as d:
        yield d
