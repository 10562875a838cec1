"""To come (describe, distances): part 1 of issue 17."""

__all__: list = []
