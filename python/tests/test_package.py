"""The package itself: version and the error hierarchy."""

import re
from pathlib import Path

import lidarloop
import pytest


def test_version_is_the_cmake_project_version():
    cmake = (Path(__file__).resolve().parents[2] / "CMakeLists.txt").read_text()
    assert lidarloop.__version__ == re.search(r"project\(lidarloop VERSION ([0-9.]+)", cmake).group(1)


@pytest.mark.parametrize(
    "name, builtin",
    [
        ("ConfigError", ValueError),
        ("FormatError", ValueError),
        ("EmptyInputError", ValueError),
        ("ReadError", OSError),
        ("WriteError", OSError),
        ("ShapeError", ValueError),
        ("DtypeError", TypeError),
        ("NonFiniteError", ValueError),
    ],
)
def test_every_error_is_a_lidarloop_error_and_its_builtin(name, builtin):
    error = getattr(lidarloop, name)
    assert issubclass(error, lidarloop.Error)
    assert issubclass(error, builtin)
    assert error.__module__ == "lidarloop"


def test_every_area_name_is_exported_at_the_top():
    for name in lidarloop.__all__:
        assert hasattr(lidarloop, name), name
