"""The lidarloop.Error hierarchy (docs/python.md, "Errors")."""

from ._lidarloop import (
    ConfigError,
    DtypeError,
    EmptyInputError,
    Error,
    FormatError,
    NonFiniteError,
    ReadError,
    ShapeError,
    WriteError,
)

__all__ = [
    "ConfigError",
    "DtypeError",
    "EmptyInputError",
    "Error",
    "FormatError",
    "NonFiniteError",
    "ReadError",
    "ShapeError",
    "WriteError",
]
