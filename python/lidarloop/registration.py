"""Part 2 of issue 17 owns this area (python/README.md): re-export its names from ._lidarloop."""

__all__: list = []
