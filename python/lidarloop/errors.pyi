class Error(Exception):
    """Base of every error lidarloop raises on purpose."""

class ConfigError(Error, ValueError): ...
class FormatError(Error, ValueError): ...
class EmptyInputError(Error, ValueError): ...

class ReadError(Error, OSError):
    file: str
    """The path of the file that could not be read."""

class WriteError(Error, OSError): ...
class ShapeError(Error, ValueError): ...
class DtypeError(Error, TypeError): ...
class NonFiniteError(Error, ValueError): ...

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
