"""The ``sim`` command group: worlds, check, and a short standalone run."""

from __future__ import annotations

import json
from pathlib import Path

import yaml
from click.testing import CliRunner

from sim.cli import sim_cli


def test_worlds_lists_shipped_worlds() -> None:
    result = CliRunner().invoke(sim_cli, ["worlds"])
    assert result.exit_code == 0
    assert "corridor" in result.output and "wall_ahead" in result.output


def test_worlds_titles_start_in_one_column_whatever_the_names_length() -> None:
    lines = CliRunner().invoke(sim_cli, ["worlds"]).output.splitlines()
    names = [line.split()[0] for line in lines]
    assert "obstacle_course" in names  # longer than the others
    title_columns = {len(line) - len(line.split(maxsplit=1)[1]) for line in lines}
    assert title_columns == {max(map(len, names)) + 2}


def test_check_good_and_bad(tmp_path: Path) -> None:
    good = CliRunner().invoke(sim_cli, ["check", "sim/worlds/obstacles.yaml"])
    assert good.exit_code == 0 and "ok" in good.output
    bad = tmp_path / "bad.yaml"
    bad.write_text("size: [6, 6]\nradius: 3\n")
    result = CliRunner().invoke(sim_cli, ["check", str(bad)])
    assert result.exit_code == 2
    assert f"{bad}:2: radius: unknown field" in result.output


def test_run_writes_record_and_svg(tmp_path: Path, ros_domain: int) -> None:
    record, svg = tmp_path / "run.json", tmp_path / "run.svg"
    result = CliRunner().invoke(sim_cli, [
        "run", "--world", "corridor", "--rtf", "0", "--duration", "3", "--domain", str(ros_domain),
        "--record", str(record), "--svg", str(svg), "--seed", "3"])
    assert result.exit_code == 0, result.output
    assert "Goal reached: no" in result.output
    assert len(json.loads(record.read_text())["trajectory"]) >= 150
    assert svg.read_text().startswith("<svg")


def test_run_records_a_bag(tmp_path: Path, ros_domain: int) -> None:
    bag = tmp_path / "bag"
    result = CliRunner().invoke(sim_cli, [
        "run", "--world", "empty_room", "--rtf", "0", "--duration", "1", "--domain",
        str(ros_domain), "--record-bag", str(bag)])
    assert result.exit_code == 0, result.output
    info = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    counts = {t["topic_metadata"]["name"]: t["message_count"]
              for t in info["topics_with_message_count"]}
    assert counts["/odom"] == counts["/tf"] >= 50 and counts["/scan"] >= 10  # 1 s or more
    assert counts["/tf_static"] == 1 and (bag / "bag_0.mcap").is_file()


def test_a_recorded_hand_run_keeps_the_commands_sent_to_the_students_node(
        tmp_path: Path, ros_domain: int) -> None:
    """`sim drive --topic /agent/cmd_vel` drives the student's node, not the robot: the
    bag has those commands too, beside the world's topics (issue 31)."""
    import threading

    import rclpy
    from geometry_msgs.msg import Twist
    from rclpy.context import Context
    from rclpy.node import Node

    from sim.cli import run_world
    from sim.worldfile import load_world

    bag = tmp_path / "bag"
    run = threading.Thread(target=run_world, args=(load_world("empty_room"),), kwargs={
        "rtf": 1.0, "duration": 3.0, "domain": ros_domain, "bag": bag})
    context = Context()
    rclpy.init(context=context, domain_id=ros_domain)
    driver = Node("driver", context=context)
    publisher = driver.create_publisher(Twist, "/agent/cmd_vel", 10)
    wish = Twist()
    wish.linear.x = 3.0
    run.start()
    try:
        while run.is_alive():  # as `sim drive` does: a command every 50 ms
            publisher.publish(wish)
            run.join(timeout=0.05)
    finally:
        driver.destroy_node()
        rclpy.try_shutdown(context=context)
    info = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    topics = {t["topic_metadata"]["name"]: t for t in info["topics_with_message_count"]}
    assert topics["/agent/cmd_vel"]["message_count"] > 10
    assert topics["/agent/cmd_vel"]["topic_metadata"]["type"] == "geometry_msgs/msg/Twist"
