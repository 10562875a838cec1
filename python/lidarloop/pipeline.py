"""To come (database, index, detector): part 1 of issue 17."""

__all__: list = []
