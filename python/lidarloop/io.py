"""Reading scans, poses and datasets."""

from ._lidarloop import (
    Dataset,
    is_scan_file,
    open_dataset,
    read_poses,
    read_scan,
    reads_bags,
)

__all__ = ["Dataset", "is_scan_file", "open_dataset", "read_poses", "read_scan", "reads_bags"]
