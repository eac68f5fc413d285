// pose_player: the robot layer end to end. Frees the legs, poses them by hand (on the virtual
// board the program turns them; on a robot you do, then press Enter), captures the pose into a
// file, holds, moves the legs home, plays the file back over 600 ms and reads the joints back.
// Run: rcb4_pose_player [/dev/ttyUSB0 [khr-3hv|kxr-l2|profile.yaml]]
//      (no device: a virtual KHR-3HV; the pose file is written to the system's temp directory)
// On a robot: the legs go limp, then move. Hold it, or let it lie on its back.
// SPDX-License-Identifier: BSL-1.0
#include "example_board.hpp"

#include <rcb4/robot/ops.hpp>
#include <rcb4/robot/profile.hpp>
#include <rcb4/transport/operations.hpp>

#include <boost/asio/post.hpp>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <future>
#include <iostream>
#include <map>
#include <string_view>
#include <thread>

using namespace std::chrono_literals;
namespace robot = rcb4::robot;
namespace t = rcb4::transport;

namespace {

/** The joints' angles as read now (measured positions), by name. */
std::map<std::string, double> angles(t::basic_client<t::serial_port>& c, const robot::joint_map& map) {
  std::map<std::string, double> out;
  for (const auto& r : t::run(c, robot::read_joints(map, robot::fields::positions)))
    if (const auto d = r.degrees()) out[r.j->name] = *d;
  return out;
}

/** Moves @p targets over @p time and returns when every joint is within 0.5° of its target (or 1 s late). */
void move_and_settle(t::basic_client<t::serial_port>& c, const robot::model& m, const robot::joint_map& map,
                     const std::vector<robot::joint_target>& targets, std::chrono::milliseconds time) {
  auto checked = robot::check_targets(m, targets, time);
  if (!robot::ok(checked)) throw std::runtime_error(std::get<robot::problem>(checked).message);
  t::run(c, robot::move_joints(std::get<std::vector<robot::joint_move>>(std::move(checked))));
  const auto deadline = std::chrono::steady_clock::now() + time + 1s;
  for (;;) {
    const auto now = angles(c, map);
    bool there = true;
    for (const auto& target : targets) there = there && std::abs(now.at(target.joint) - target.degrees) < 0.5;
    if (there) return;
    if (std::chrono::steady_clock::now() > deadline) throw std::runtime_error("the joints did not reach the pose");
    std::this_thread::sleep_for(20ms);  // the board's outputs move every output period (10 ms here)
  }
}

}  // namespace

int main(int argc, char** argv) try {
  if (argc > 1 && argv[1][0] == '-') {
    std::printf("usage: rcb4_pose_player [DEVICE [khr-3hv|kxr-l2|PROFILE.yaml]]  (no device: a virtual KHR-3HV)\n");
    return std::string_view(argv[1]) == "--help" || std::string_view(argv[1]) == "-h" ? 0 : 2;
  }
  example::connection board(argc > 1 && argv[1][0] ? 2 : 1, argv);
  auto& c = *board;
  const auto model = robot::open_profile(argc > 2 ? argv[2] : "khr-3hv");
  const auto map = t::run(c, robot::locate_joints(model));
  auto legs = std::get<std::vector<const robot::joint*>>(model.select("legs"));
  std::erase_if(legs, [&](const robot::joint* j) { return !map.block_of(*j); });
  if (legs.empty()) throw std::runtime_error("the board has no servo for the legs of the " + model.name());
  rcb4::servo_mask mask;
  for (const auto* j : legs) mask.insert(j->ics);

  // 1. Free the legs and pose them by hand.
  t::run(c, rcb4::ops::set_servo_power(rcb4::ops::power_state::free, mask));
  if (board.board) {
    // The virtual robot: "turn" hips, knees and ankles into a crouch, on the board's own thread.
    std::promise<void> turned;
    boost::asio::post(board.board_io->context(), [&] {
      for (const auto* j : legs) {
        const double deg = j->name.find("knee") != std::string::npos    ? 60.0
                           : j->name.find("pitch") != std::string::npos ? -30.0
                                                                        : 0.0;
        board.board->turn_by_hand(j->ics, std::get<rcb4::servo_position>(robot::to_position(*j, deg)).value());
      }
      turned.set_value();
    });
    turned.get_future().wait();
  } else {
    std::printf("%zu leg joints are free: pose them by hand, then press Enter\n", legs.size());
    std::string line;
    std::getline(std::cin, line);
  }

  // 2. Capture the pose into a file, then hold.
  robot::pose captured{model.name(), {}, 600ms};
  const auto now = angles(c, map);
  for (const auto* j : legs) captured.joints.emplace_back(j->name, now.at(j->name));
  const auto file = std::filesystem::temp_directory_path() / "rcb4_pose_player.yaml";
  robot::save_pose(file, captured);
  t::run(c, rcb4::ops::set_servo_power(rcb4::ops::power_state::hold, mask));
  std::printf("captured %zu joints into %s\n", captured.joints.size(), file.c_str());

  // 3. Legs home (0 degrees) over 300 ms.
  std::vector<robot::joint_target> home;
  for (const auto* j : legs) home.push_back({j->name, std::clamp(0.0, j->lower, j->upper), std::nullopt});
  move_and_settle(c, model, map, home, 300ms);
  std::printf("legs home\n");

  // 4. Play the file back with its timing, and read the joints back.
  const auto loaded = robot::load_pose(file, model);
  std::vector<robot::joint_target> pose;
  for (const auto& [name, deg] : loaded.joints) pose.push_back({name, deg, std::nullopt});
  const auto start = std::chrono::steady_clock::now();
  move_and_settle(c, model, map, pose, loaded.time.value_or(1000ms));
  const auto took = std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - start);
  const auto back = angles(c, map);
  double worst = 0;
  for (const auto& [name, deg] : loaded.joints) {
    const double err = back.at(name) - deg;
    worst = std::max(worst, std::abs(err));
    std::printf("  %-18s captured %+7.2f  now %+7.2f  (%+.2f)\n", name.c_str(), deg, back.at(name), err);
  }
  std::printf("played in %lld ms (the file says %lld ms)\n", static_cast<long long>(took.count()),
              static_cast<long long>(loaded.time.value_or(1000ms).count()));
  if (worst > 1.0) {
    std::printf("a joint is %.2f degrees away from the captured pose\n", worst);
    return 2;
  }
  std::printf("every joint within 1 degree of the captured pose (worst %.2f)\n", worst);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "pose_player: %s\n", e.what());
  return 1;
}
