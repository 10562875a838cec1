#!/usr/bin/python3
"""Writes ROS 1 bags for lidarloop's bag tests with Debian's python3-rosbag (run it with
/usr/bin/python3, which sees Debian's rosbag, sensor_msgs and nav_msgs).

  write_bag.py from-kitti FOLDER OUT.bag [--topic /points] [--odometry-topic /odom] [--float64]
                                         [--organised] [--compression none|bz2|lz4]
      The scans of a KITTI-layout folder (velodyne/*.bin, as `lidarloop simulate` writes it) as
      sensor_msgs/PointCloud2 messages stamped with times.txt (else 0.1 s apart), and with
      --odometry-topic its poses_odometry.txt as nav_msgs/Odometry at the same stamps.
      --float64 writes x y z as FLOAT64 (with padding), --organised as 2 rows with a NaN point
      added to each: the same points for lidarloop either way.
  write_bag.py case NAME OUT.bag
      A small bag: tiny (a fuzzer seed), or one kind of bad input: wrong-type, no-xyz, no-clouds, two-clouds,
      short-odometry, big-endian.
"""
import argparse
import math
import pathlib
import struct
import sys

import rosbag
import rospy
from nav_msgs.msg import Odometry
from sensor_msgs.msg import PointCloud2, PointField

FLOAT32, FLOAT64 = 7, 8
RECORDED_FROM_S = 1.6e9  # recording times (not the header stamps) from 2020-09-13


def cloud_message(points, stamp, float64=False, organised=False, big_endian=False):
    """points: a list of (x, y, z) tuples."""
    msg = PointCloud2()
    msg.header.stamp = stamp
    msg.header.frame_id = "lidar"
    if float64:  # x y z as doubles, then 4 bytes of intensity and 4 of padding
        msg.fields = [PointField("x", 0, FLOAT64, 1), PointField("y", 8, FLOAT64, 1),
                      PointField("z", 16, FLOAT64, 1), PointField("intensity", 24, FLOAT32, 1)]
        msg.point_step, fmt = 32, "<dddf4x"
    else:
        msg.fields = [PointField("x", 0, FLOAT32, 1), PointField("y", 4, FLOAT32, 1),
                      PointField("z", 8, FLOAT32, 1), PointField("intensity", 12, FLOAT32, 1)]
        msg.point_step, fmt = 16, "<ffff"
    if big_endian:
        fmt = ">" + fmt[1:]
    rows = [list(points)]
    if organised:  # two rows of equal width, each with a NaN point (no return)
        half = (len(points) + 1) // 2
        rows = [list(points[:half]), list(points[half:])]
        while len(rows[1]) < len(rows[0]):
            rows[1].append((math.nan, math.nan, math.nan))
        for row in rows:
            row.append((math.nan, math.nan, math.nan))
    msg.height, msg.width = len(rows), len(rows[0])
    msg.row_step = msg.point_step * msg.width
    msg.is_bigendian = big_endian
    msg.data = b"".join(struct.pack(fmt, x, y, z, 0.0) for row in rows for x, y, z in row)
    msg.is_dense = not organised
    return msg


def read_bin(path):
    data = path.read_bytes()
    return [struct.unpack_from("<fff", data, 16 * i) for i in range(len(data) // 16)]


def kitti_poses(path):
    poses = []
    for line in path.read_text().splitlines():
        values = [float(v) for v in line.split()]
        if len(values) == 12:
            poses.append(values)
    return poses


def quaternion(m):
    """(x, y, z, w) of the rotation in a row-major 3x4 matrix m."""
    r = [[m[0], m[1], m[2]], [m[4], m[5], m[6]], [m[8], m[9], m[10]]]
    trace = r[0][0] + r[1][1] + r[2][2]
    if trace > 0:
        s = 2.0 * math.sqrt(trace + 1.0)
        return ((r[2][1] - r[1][2]) / s, (r[0][2] - r[2][0]) / s, (r[1][0] - r[0][1]) / s, s / 4)
    i = max(range(3), key=lambda k: r[k][k])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2.0 * math.sqrt(1.0 + r[i][i] - r[j][j] - r[k][k])
    q = [0.0, 0.0, 0.0]
    q[i] = s / 4
    q[j] = (r[j][i] + r[i][j]) / s
    q[k] = (r[k][i] + r[i][k]) / s
    return (q[0], q[1], q[2], (r[k][j] - r[j][k]) / s)


def odometry_message(m, stamp):
    msg = Odometry()
    msg.header.stamp = stamp
    msg.header.frame_id = "odom"
    msg.child_frame_id = "lidar"
    p = msg.pose.pose
    p.position.x, p.position.y, p.position.z = m[3], m[7], m[11]
    p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w = quaternion(m)
    return msg


def from_kitti(args):
    folder = pathlib.Path(args.folder)
    scans = sorted((folder / "velodyne").glob("*.bin"))
    if not scans:
        sys.exit(f"{folder}: no velodyne/*.bin")
    times_file = folder / "times.txt"
    times = ([float(t) for t in times_file.read_text().split()] if times_file.exists()
             else [0.1 * i for i in range(len(scans))])
    odometry = kitti_poses(folder / "poses_odometry.txt") if args.odometry_topic else []
    with rosbag.Bag(args.out, "w", compression=args.compression) as bag:
        for i, scan in enumerate(scans):
            stamp = rospy.Time.from_sec(times[i])
            # The time a message was recorded, which the bag's index holds: rosbag_storage drops
            # messages recorded at time 0 ("invalid time"), and simulated times start at 0.
            recorded = rospy.Time.from_sec(RECORDED_FROM_S + times[i])
            bag.write(args.topic, cloud_message(read_bin(scan), stamp, args.float64,
                                                args.organised), recorded)
            if odometry:
                bag.write(args.odometry_topic, odometry_message(odometry[i], stamp), recorded)


def write_case(name, out, compression):
    points = [(1.0 + i, 2.0, 0.5 * i) for i in range(20)]
    identity = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0]
    with rosbag.Bag(out, "w", compression=compression) as bag:
        for i in range(5):
            stamp = rospy.Time.from_sec(100.0 + i)
            if name == "tiny":  # a seed for the fuzzer: 2 scans of 3 points, odometry around them
                if i < 2:
                    bag.write("/points", cloud_message(points[:3], stamp, float64=i == 1), stamp)
                if i < 3:
                    odometry = list(identity)
                    odometry[3] = 0.5 * i
                    bag.write("/odom", odometry_message(odometry, rospy.Time.from_sec(99.5 + i)),
                              stamp)
            elif name == "wrong-type":
                bag.write("/points", odometry_message(identity, stamp), stamp)
            elif name == "no-xyz":
                msg = cloud_message(points, stamp)
                msg.fields[2].name = "intensity_2"
                bag.write("/points", msg, stamp)
            elif name == "no-clouds":  # no PointCloud2 message at all
                bag.write("/odom", odometry_message(identity, stamp), stamp)
            elif name == "two-clouds":
                bag.write("/front", cloud_message(points, stamp), stamp)
                bag.write("/rear", cloud_message(points, stamp), stamp)
            elif name == "short-odometry":  # odometry from 101 s, scans from 100 s
                bag.write("/points", cloud_message(points, stamp), stamp)
                if i > 0:
                    bag.write("/odom", odometry_message(identity, stamp), stamp)
            elif name == "big-endian":
                bag.write("/points", cloud_message(points, stamp, big_endian=True), stamp)
            else:
                sys.exit(f"unknown case {name}")


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    kitti = sub.add_parser("from-kitti")
    kitti.add_argument("folder")
    kitti.add_argument("out")
    kitti.add_argument("--topic", default="/points")
    kitti.add_argument("--odometry-topic", default="")
    kitti.add_argument("--float64", action="store_true")
    kitti.add_argument("--organised", action="store_true")
    kitti.add_argument("--compression", default="none", choices=["none", "bz2", "lz4"])
    case = sub.add_parser("case")
    case.add_argument("name")
    case.add_argument("out")
    case.add_argument("--compression", default="none", choices=["none", "bz2", "lz4"])
    args = parser.parse_args()
    if args.command == "from-kitti":
        from_kitti(args)
    else:
        write_case(args.name, args.out, args.compression)


if __name__ == "__main__":
    main()
