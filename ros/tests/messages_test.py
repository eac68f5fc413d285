#!/usr/bin/python3
# The ROS messages rcb4_ros generates (ros/messages, ros/gen_messages.py) have the md5sums of the
# published ones, so that a client built with the real control_msgs or kxr_controller talks to
# the node. The expected values are the published ones: control_msgs 1.5.2 (kinetic-devel, which
# melodic and noetic build; the same definitions since 1.3.0), as generated code in public
# repositories carries them; kxr_controller's from iory/rcb4's generated code where published.
#   messages_test.py GENERATED_DIR
# SPDX-License-Identifier: BSL-1.0
import os
import sys

sys.path.append(sys.argv[1])  # last: as the node does, a system's real package comes first
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tests", "integration"))
from checks import check, finish  # noqa: E402

PUBLISHED = {
    "control_msgs/FollowJointTrajectoryAction": "bc4f9b743838566551c0390c65f1a248",
    "control_msgs/FollowJointTrajectoryActionGoal": "cff5c1d533bf2f82dd0138d57f4304bb",
    "control_msgs/FollowJointTrajectoryActionResult": "c4fb3b000dc9da4fd99699380efcc5d9",
    "control_msgs/FollowJointTrajectoryActionFeedback": "d8920dc4eae9fc107e00999cce4be641",
    "control_msgs/FollowJointTrajectoryGoal": "69636787b6ecbde4d61d711979bc7ecb",
    "control_msgs/FollowJointTrajectoryResult": "493383b18409bfb604b4e26c676401d2",
    "control_msgs/FollowJointTrajectoryFeedback": "10817c60c2486ef6b33e97dcd87f4474",
    "control_msgs/JointTolerance": "f544fe9c16cf04547e135dd6063ff5be",
    # What scikit-robot's ROSRobotInterfaceBase (kxr_controller's `ri`) imports from control_msgs.
    "control_msgs/JointTrajectoryControllerState": "10817c60c2486ef6b33e97dcd87f4474",
    "control_msgs/SingleJointPositionAction": "c4a786b7d53e5d0983decf967a5a779e",
    "control_msgs/SingleJointPositionActionGoal": "4b0d3d091471663e17749c1d0db90f61",
    "control_msgs/SingleJointPositionActionResult": "1eb06eeff08fa7ea874431638cb52332",
    "control_msgs/SingleJointPositionActionFeedback": "3503b7cf8972f90d245850a5d8796cfa",
    "control_msgs/SingleJointPositionGoal": "fbaaa562a23a013fd5053e5f72cbb35c",
    "control_msgs/SingleJointPositionResult": "d41d8cd98f00b204e9800998ecf8427e",
    "control_msgs/SingleJointPositionFeedback": "8cee65610a3d08e0a1bded82f146f1fd",
    "kxr_controller/Stretch": "9b2b730aeb11dca161b5a118a2171acb",
    "kxr_controller/StretchGoal": "c548d78132f076011af76f4175ffa5b0",
    "kxr_controller/AdjustAngleVectorGoal": "cf618411b2b5e77c4c269ff22a27ed58",
    # servo_states: ServoStateArray's is the published one (it covers ServoState's text); ServoState's
    # and ServoOnOff's (the fullbody_controller/servo_on_off_real_interface/state message) are what
    # genpy gives iory/rcb4's own .msg files.
    "kxr_controller/ServoStateArray": "c49987abc073bf0afcf190de7df7c47c",
    "kxr_controller/ServoState": "ce152110c70fb30775e21de46928de76",
    "kxr_controller/ServoOnOff": "29bb8c289c7a237569042d21176cbdd5",
}

for full, md5 in PUBLISHED.items():
    pkg, name = full.split("/")
    try:
        cls = getattr(__import__(f"{pkg}.msg", fromlist=[name]), name)
        got = cls._md5sum
    except (ImportError, AttributeError) as e:
        got = f"not importable: {e}"
    check(got == md5, f"{full}: md5sum {got} (published {md5})")

# The goal constants a client compares error codes with.
from control_msgs.msg import FollowJointTrajectoryResult as R  # noqa: E402
check((R.SUCCESSFUL, R.INVALID_GOAL, R.INVALID_JOINTS, R.PATH_TOLERANCE_VIOLATED, R.GOAL_TOLERANCE_VIOLATED)
      == (0, -1, -2, -4, -5), "FollowJointTrajectoryResult's error codes")
# A goal serialises and reads back (genpy's code over the system's trajectory_msgs).
import io  # noqa: E402
from control_msgs.msg import FollowJointTrajectoryGoal, JointTolerance  # noqa: E402
g = FollowJointTrajectoryGoal()
g.trajectory.joint_names = ["left_knee"]
g.goal_tolerance = [JointTolerance(name="left_knee", position=0.02)]
buf = io.BytesIO()
g.serialize(buf)
back = FollowJointTrajectoryGoal().deserialize(buf.getvalue())
check(back.trajectory.joint_names == ["left_knee"] and back.goal_tolerance[0].position == 0.02, "a goal round-trips")
finish()
