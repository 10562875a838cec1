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


AREAS = ["app", "descriptors", "errors", "eval", "io", "pipeline", "posegraph", "registration", "sim"]


@pytest.mark.parametrize("area", AREAS)
def test_each_area_stub_declares_exactly_its_exports(area):
    """The .pyi of an area declares the names its module exports, and its classes' methods
    exist on the real classes, so that editors complete what is there."""
    import ast
    import importlib

    module = importlib.import_module(f"lidarloop.{area}")
    stub = ast.parse((Path(lidarloop.__file__).parent / f"{area}.pyi").read_text())
    declared = {node.name for node in stub.body if isinstance(node, (ast.ClassDef, ast.FunctionDef))}
    assert declared == set(module.__all__)
    for node in stub.body:
        if isinstance(node, ast.ClassDef):
            cls = getattr(module, node.name)
            for member in node.body:
                if isinstance(member, ast.FunctionDef):
                    assert hasattr(cls, member.name), f"{node.name}.{member.name}"
