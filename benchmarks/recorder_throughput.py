"""How many messages per second recorder_node keeps, on one topic, without loss.

    source scripts/env.sh && python benchmarks/recorder_throughput.py [--seconds 5]
        [--rates 1000 2000 5000 10000 20000] [--type rotor|odom]

For each rate [msg/s] a fresh recorder process records one topic while this process publishes
RotorCommand (4 rotors, ~110 B of CDR) or Odometry (~720 B) at that rate, reliable +
transient_local, depth 1000, as our nodes do; then SIGINT, and the bag is read back with rosbags.
Prints published, recorded, lost, achieved publish rate and bag size.
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import tempfile
import time
from pathlib import Path

import rclpy
from multilift_msgs.msg import RotorCommand
from nav_msgs.msg import Odometry
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rosbags.highlevel import AnyReader

ROOT = Path(__file__).resolve().parents[1]
RECORDER = ROOT / 'ros_ws' / 'install' / 'multilift_sim' / 'lib' / 'multilift_sim' / 'recorder_node'
TYPES = {'rotor': (RotorCommand, 'multilift_msgs/msg/RotorCommand'),
         'odom': (Odometry, 'nav_msgs/msg/Odometry')}


def run(rate: float, seconds: float, kind: str, workdir: Path, node) -> dict:
    msg_type, type_name = TYPES[kind]
    topic = f'/bench/{kind}_{int(rate)}'
    bag = workdir / f'{kind}_{int(rate)}'
    recorder = subprocess.Popen(
        [str(RECORDER), '--ros-args', '-p', f'bag:={bag}', '-p', 'all:=false',
         '-p', f"topics:=['{topic}|{type_name}']"],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
    publisher = node.create_publisher(msg_type, topic, qos)
    end = time.monotonic() + 30.0
    while publisher.get_subscription_count() == 0 and time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.05)
    time.sleep(3.0)  # the recorder's side of discovery can lag the publisher's by ~2.5 s
    msg = msg_type()
    if kind == 'rotor':
        msg.angular_velocity, msg.saturated = [400.0] * 4, [False] * 4
    count, start = 0, time.monotonic()
    while (now := time.monotonic()) - start < seconds:
        due = int((now - start) * rate) + 1
        while count < due:
            msg.header.stamp.sec = count
            publisher.publish(msg)
            count += 1
    elapsed = time.monotonic() - start
    time.sleep(1.0)
    os.killpg(recorder.pid, signal.SIGINT)
    recorder.wait(timeout=30)
    node.destroy_publisher(publisher)
    with AnyReader([bag]) as reader:
        recorded = reader.message_count
    size = sum(p.stat().st_size for p in bag.iterdir())
    return {'rate': rate, 'published': count, 'publish_rate': count / elapsed,
            'recorded': recorded, 'lost': count - recorded, 'bag_bytes': size}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--seconds', type=float, default=5.0)
    parser.add_argument('--rates', type=float, nargs='+', default=[1000, 2000, 5000, 10000])
    parser.add_argument('--type', choices=sorted(TYPES), default='rotor')
    args = parser.parse_args()
    rclpy.init()
    node = rclpy.create_node('recorder_benchmark')
    print(f'{"target/s":>9} {"published":>9} {"pub/s":>8} {"recorded":>9} {"lost":>6} '
          f'{"bag kB":>8} {"B/msg":>6}')
    with tempfile.TemporaryDirectory() as tmp:
        for rate in args.rates:
            r = run(rate, args.seconds, args.type, Path(tmp), node)
            print(f'{r["rate"]:9.0f} {r["published"]:9d} {r["publish_rate"]:8.0f} '
                  f'{r["recorded"]:9d} {r["lost"]:6d} {r["bag_bytes"] / 1000:8.1f} '
                  f'{r["bag_bytes"] / max(r["recorded"], 1):6.1f}', flush=True)
    node.destroy_node()
    rclpy.try_shutdown()


if __name__ == '__main__':
    main()
