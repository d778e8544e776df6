"""A ROS 2 node that drives a robot with tlmpc's executor through its bridge.

Runs with the ROS 2 distribution's own Python (rclpy comes with ROS 2, not from PyPI, and may
be an older Python than tlmpc needs): it starts ``python -m tlmpc.runtime.bridge OUT`` with the
interpreter where tlmpc is installed and speaks the bridge's JSON lines through a pipe
(protocol: ``tlmpc/runtime/bridge.py``).  At every tick it looks the robot up in the mission's
frame with tf2 (``base_link`` in ``map`` by default), sends the pose, and publishes the command
as ``geometry_msgs/msg/Twist`` on ``cmd_vel``; on an error line, a stopped task, or a bridge
that has gone, it publishes a zero Twist.

    python3 tools/ros2/tlmpc_bridge_node.py --ros-args -p output:=/path/to/out \
        -p tlmpc_python:=/path/to/venv/bin/python

Parameters: ``output`` (the compiled output folder), ``tlmpc_python`` (default ``python3``),
``frame`` (``map``), ``base_frame`` (``base_link``), ``rate`` (Hz, 20).
"""

from __future__ import annotations

import json
import math
import subprocess
from typing import Any

import rclpy  # type: ignore[import-not-found]
from geometry_msgs.msg import Twist  # type: ignore[import-not-found]
from rclpy.node import Node  # type: ignore[import-not-found]
from rclpy.time import Time  # type: ignore[import-not-found]
from tf2_ros import Buffer, TransformListener  # type: ignore[import-not-found]

#: Statuses after which the robot must not move.
STOPPED = {"no_plan", "violated"}


class TlmpcBridgeNode(Node):  # type: ignore[misc]
    """Pose from tf2 in, ``cmd_vel`` out, the executor behind a pipe."""

    def __init__(self) -> None:
        super().__init__("tlmpc_bridge")
        output = self.declare_parameter("output", "out").value
        python = self.declare_parameter("tlmpc_python", "python3").value
        self.frame = self.declare_parameter("frame", "map").value
        self.base_frame = self.declare_parameter("base_frame", "base_link").value
        rate = float(self.declare_parameter("rate", 20.0).value)
        self.bridge = subprocess.Popen(
            [python, "-m", "tlmpc.runtime.bridge", output],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        hello = self._read()
        if hello is None or hello.get("format") != "tlmpc.bridge/1":
            raise RuntimeError(f"tlmpc bridge did not start for {output!r}")
        self.unicycle = hello["model"] == "unicycle"
        self.tf = Buffer()
        TransformListener(self.tf, self)
        self.cmd = self.create_publisher(Twist, "cmd_vel", 10)
        self.create_timer(1.0 / rate, self.step)

    def _read(self) -> dict[str, Any] | None:
        assert self.bridge.stdout is not None
        line = self.bridge.stdout.readline()
        return json.loads(line) if line else None

    def step(self) -> None:
        try:
            pose = self.tf.lookup_transform(self.frame, self.base_frame, Time()).transform
        except Exception as exc:  # no transform yet: keep still
            self.get_logger().warn(f"no pose: {exc}")
            self.cmd.publish(Twist())
            return
        q = pose.rotation
        yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
        xy = [pose.translation.x, pose.translation.y]
        request = {"t": self.get_clock().now().nanoseconds / 1e9, "pose": [*xy, yaw]}
        if not self.unicycle:
            request["pose"] = xy
        reply: dict[str, Any] | None = None
        try:
            assert self.bridge.stdin is not None
            self.bridge.stdin.write(json.dumps(request) + "\n")
            self.bridge.stdin.flush()
            reply = self._read()
        except (BrokenPipeError, ValueError):
            reply = None
        msg = Twist()
        if reply is None or "error" in reply or reply["status"] in STOPPED:
            self.get_logger().error(f"tlmpc bridge: {reply}")
        elif self.unicycle:
            msg.linear.x, msg.angular.z = reply["command"]
        else:  # a holonomic base: the velocity in the map frame, turned into the robot's
            vx, vy = reply["command"]
            msg.linear.x = math.cos(yaw) * vx + math.sin(yaw) * vy
            msg.linear.y = -math.sin(yaw) * vx + math.cos(yaw) * vy
        self.cmd.publish(msg)


def main() -> None:
    rclpy.init()
    node = TlmpcBridgeNode()
    try:
        rclpy.spin(node)
    finally:
        node.cmd.publish(Twist())
        if node.bridge.stdin is not None:
            node.bridge.stdin.close()
        node.bridge.wait(timeout=5)
        rclpy.shutdown()


if __name__ == "__main__":
    main()
