"""A ROS 2 node between a robot and `bayesgrasp serve` (not run by the tests: there is no ROS in
bayesgrasp's environment; it needs rclpy, sensor_msgs, std_msgs and moveit_msgs, and only the
standard library of bayesgrasp: ``bayesgrasp/client.py`` can be copied next to it).

It starts an episode, prints its first grasp as a ``moveit_msgs/Grasp`` (and publishes it on
``~/grasp``), then after each grasp the robot executed takes the hand's ``sensor_msgs/JointState``
(topic ``joint_states``) and the lift verdict (``std_msgs/Bool`` on ``lifted``), forwards them as
one observation and prints the next grasp, until the episode ends.

    ros2 run ... ros2_grasp_node.py --ros-args -p url:=http://127.0.0.1:8765 \\
        -p token_file:=episodes/.token -p object:=cylinder -p estimate:="[0.045, -0.03, 0.9]"
"""
import uuid

import rclpy
from builtin_interfaces.msg import Duration
from geometry_msgs.msg import Vector3Stamped
from moveit_msgs.msg import Grasp, GripperTranslation
from rclpy.node import Node
from sensor_msgs.msg import JointState
from std_msgs.msg import Bool
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from bayesgrasp.client import Client

LIFT = 0.1   # m: the retreat after closing is the lift test's


def _posture(names, positions, seconds: float) -> JointTrajectory:
    t = JointTrajectory()
    t.joint_names = list(names)
    p = JointTrajectoryPoint()
    p.positions = [float(v) for v in positions]
    p.time_from_start = Duration(sec=int(seconds))
    t.points = [p]
    return t


def _translation(frame: str, distance: float) -> GripperTranslation:
    g = GripperTranslation()
    g.direction = Vector3Stamped()
    g.direction.header.frame_id = frame
    g.direction.vector.z = 1.0
    g.desired_distance, g.min_distance = float(distance), float(distance) / 2
    return g


def grasp_msg(nxt: dict) -> Grasp:
    """The service's ``next`` as a moveit_msgs/Grasp (the README's table of fields)."""
    rec = nxt["grasp"]
    names, closed, opened = ((rec["urdf"]["joint_names"], rec["urdf"]["joint_positions"],
                              rec["urdf"]["pregrasp_joint_positions"]) if "urdf" in rec else
                             (rec["joint_names"], rec["joint_positions"], rec["pregrasp"]["joint_positions"]))
    g = Grasp()
    g.id = f"attempt-{nxt['attempt']}"
    g.grasp_pose.header.frame_id = rec["frame"]
    g.grasp_pose.pose.position.x, g.grasp_pose.pose.position.y, g.grasp_pose.pose.position.z = rec["position"]
    q = g.grasp_pose.pose.orientation
    q.x, q.y, q.z, q.w = rec["quaternion_xyzw"]
    g.pre_grasp_posture = _posture(names, opened, 0.0)
    g.grasp_posture = _posture(names, closed, 1.0)
    g.pre_grasp_approach = _translation("hand", rec["pregrasp"]["distance"])
    g.post_grasp_retreat = _translation(rec["frame"], LIFT)
    g.grasp_quality = float(nxt.get("predicted_stability", nxt.get("objective", 0.0)))
    return g


class GraspNode(Node):
    def __init__(self):
        super().__init__("bayesgrasp_grasp_node")
        p = {name: self.declare_parameter(name, default).value for name, default in
             (("url", "http://127.0.0.1:8765"), ("token_file", "episodes/.token"), ("object", "cylinder"),
              ("estimate", [0.0, 0.0, 0.0]), ("method", "stability"), ("attempts", 4))}
        with open(p["token_file"]) as f:
            self.client = Client(p["url"], f.read().strip())
        self.joints = None
        self.grasps = self.create_publisher(Grasp, "~/grasp", 1)
        self.create_subscription(JointState, "joint_states", self.on_joints, 10)
        self.create_subscription(Bool, "lifted", self.on_lifted, 1)
        self.episode = self.client.new_episode(object=p["object"], estimate=list(p["estimate"]), method=p["method"],
                                               attempts=int(p["attempts"]))
        self.show(self.episode)

    def on_joints(self, msg: JointState) -> None:
        """The latest hand reading, in the grasp's joint order (the names the service gave)."""
        if self.episode["next"] is None:
            return
        rec = self.episode["next"]["grasp"]
        order = rec["urdf"]["joint_names"] if "urdf" in rec else rec["joint_names"]
        got = dict(zip(msg.name, msg.position))
        if all(n in got for n in order):
            self.joints = [got[n] for n in order]

    def on_lifted(self, msg: Bool) -> None:
        """The robot's verdict on the grasp it executed: forward the reading, show the next grasp."""
        if self.episode["next"] is None or self.joints is None:
            self.get_logger().warn("no grasp pending or no joint reading yet; verdict ignored")
            return
        self.episode = self.client.observe(self.episode["id"], self.joints, msg.data, request_id=uuid.uuid4().hex)
        self.joints = None
        self.show(self.episode)

    def show(self, episode: dict) -> None:
        if episode["next"] is None:
            self.get_logger().info(f"episode {episode['id']}: {episode['status']} after "
                                   f"{episode['attempts_made']} grasp(s)")
            return
        msg = grasp_msg(episode["next"])
        self.grasps.publish(msg)
        print(msg, flush=True)


def main():
    rclpy.init()
    node = GraspNode()
    try:
        rclpy.spin(node)
    finally:
        node.destroy_node()
        rclpy.shutdown()


if __name__ == "__main__":
    main()
