"""Shared fixtures of the Python tests: the test data folder and the built CLI (for parity)."""

import os
from pathlib import Path

import pytest

REPOSITORY = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def data_dir():
    """tests/data of the checkout (CTest passes it as LIDARLOOP_TEST_DATA_DIR)."""
    return Path(os.environ.get("LIDARLOOP_TEST_DATA_DIR", REPOSITORY / "tests" / "data"))


@pytest.fixture(scope="session")
def cli():
    """The `lidarloop` executable (CTest passes it as LIDARLOOP_CLI); skips when not built."""
    path = Path(os.environ.get("LIDARLOOP_CLI", REPOSITORY / "build" / "cli" / "lidarloop"))
    if not path.is_file():
        pytest.skip(f"the lidarloop CLI is not built ({path})")
    return path
