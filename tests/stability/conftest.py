import pytest


@pytest.fixture
def out(tmp_path):
    """A fresh output directory per case."""
    return str(tmp_path)
