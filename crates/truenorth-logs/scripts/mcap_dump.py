#!/usr/bin/env python3
"""Decode an MCAP file's ROS 2 messages with the reference Python reader (`mcap` and
`mcap-ros2-support`) and print them as JSON, so that a test can compare them with what the
Rust reader decodes.

Usage: python3 mcap_dump.py FILE.mcap
Prints {"topics": {TOPIC: {"schema": NAME, "messages": [[log_time_ns, ...numbers]]}}}
where the numbers per type are:
  sensor_msgs/msg/Imu:            sec, nanosec, qx, qy, qz, qw, wx, wy, wz, ax, ay, az
  sensor_msgs/msg/MagneticField:  sec, nanosec, bx, by, bz
  nav_msgs/msg/Odometry:          sec, nanosec, px, py, pz, qx, qy, qz, qw, vx, vy, vz, wx, wy, wz
  anything else:                  (no numbers)
Exits 3 (and says so) when the Python packages are not installed.
"""
import json
import sys

try:
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory
except ImportError as e:  # the caller reports the skip
    print(f"SKIPPED: python mcap readers absent ({e}); pip install mcap mcap-ros2-support", file=sys.stderr)
    sys.exit(3)


def numbers(schema, m):
    stamp = [m.header.stamp.sec, m.header.stamp.nanosec] if hasattr(m, "header") else []
    v = lambda x: [x.x, x.y, x.z]
    q = lambda x: [x.x, x.y, x.z, x.w]
    if schema.endswith("Imu"):
        return stamp + q(m.orientation) + v(m.angular_velocity) + v(m.linear_acceleration)
    if schema.endswith("MagneticField"):
        return stamp + v(m.magnetic_field)
    if schema.endswith("Odometry"):
        p = m.pose.pose
        t = m.twist.twist
        return stamp + v(p.position) + q(p.orientation) + v(t.linear) + v(t.angular)
    return []


def main(path):
    out = {}
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for schema, channel, message, decoded in reader.iter_decoded_messages():
            topic = out.setdefault(channel.topic, {"schema": schema.name, "messages": []})
            topic["messages"].append([message.log_time] + numbers(schema.name, decoded))
    json.dump({"topics": out}, sys.stdout)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
