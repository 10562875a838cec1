"""The descriptor database, its nearest-neighbour index and the online loop detector."""

from ._lidarloop import DescriptorDatabase, LoopDetector, LoopQuery, Neighbor, NeighborIndex

__all__ = ["DescriptorDatabase", "LoopDetector", "LoopQuery", "Neighbor", "NeighborIndex"]
