"""A robot controller that decides its robots' trades for their market agents (docs/ros.md).

It uses nothing of infomarket: only rclpy and std_msgs, as a robot's own code would (the same two
topics can be served from C++, Rust or anything else with a ROS 2 client). For each robot it listens on
``/robot_N/market/ask`` and answers on ``/robot_N/market/decision``, both ``std_msgs/String`` holding
JSON: a question ``{"id", "question": "sell" | "buy", ...facts}``, an answer ``{"id", "question",
"yes": true | false}``. Its rule here is a simple one: refuse the kinds of trade named by ``--refuse``,
and buy only information no older than ``--max-age`` steps; a real controller would use its own sensing.

    python examples/ros_controller.py --robots 0-2 --max-age 500 --log answers.jsonl

Start agents with ``infomarket ros agent --controller ...`` (or a swarm with ``--controlled``) in the
same ROS domain. ``--log`` appends every question with its answer, one JSON object a line.
"""
import argparse
import json

import rclpy
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String


def robot_list(text):
    robots = []
    for part in text.split(","):
        lo, _, hi = part.partition("-")
        robots += range(int(lo), int(hi or lo) + 1)
    return robots


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=robot_list, required=True, help="robots served, e.g. 0-2 or 0,4")
    parser.add_argument("--refuse", action="append", choices=["sell", "buy"], default=[],
                        help="answer no to every question of this kind (may be repeated)")
    parser.add_argument("--max-age", type=int, help="buy only information at most this many steps old")
    parser.add_argument("--log", help="append each question and its answer to this file (JSON lines)")
    args = parser.parse_args()

    rclpy.init()
    node = rclpy.create_node("robot_controller")
    qos = QoSProfile(depth=100, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.RELIABLE)

    def serve(robot):
        answers = node.create_publisher(String, f"/robot_{robot}/market/decision", qos)

        def on_question(msg):
            q = json.loads(msg.data)
            yes = q["question"] not in args.refuse
            if q["question"] == "buy" and args.max_age is not None:
                yes = yes and q["age"] <= args.max_age
            answers.publish(String(data=json.dumps({"id": q["id"], "question": q["question"], "yes": yes})))
            if args.log:
                with open(args.log, "a") as f:
                    f.write(json.dumps({"robot": robot, **q, "yes": yes}) + "\n")

        node.create_subscription(String, f"/robot_{robot}/market/ask", on_question, qos)

    for robot in args.robots:
        serve(robot)
    print(f"controller ready for robots {args.robots}", flush=True)
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
