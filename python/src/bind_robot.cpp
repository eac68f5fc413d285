// pyrcb4: poses (capture, play, the tool's JSON/YAML pose files), trims, scan, servo blocks and
// the control loop, bound to Python.
// SPDX-License-Identifier: BSL-1.0
#include "common.hpp"

#include <rcb4/robot/services/moves.hpp>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <limits>

using namespace pybind11::literals;

namespace pyrcb4 {
namespace {

/** A pose from Python: a dict {joint: degrees}, or a pose file (str or path); its time when the file says. */
std::pair<std::vector<std::pair<std::string, double>>, std::optional<double>> pose_of(board& b,
                                                                                      const py::object& pose) {
  std::vector<std::pair<std::string, double>> joints;
  // What load_pose returns: {"robot", "joints": {...}, "time"}.
  if (py::isinstance<py::dict>(pose) && pose.contains("joints") && py::isinstance<py::dict>(pose["joints"])) {
    auto inner = pose_of(b, pose["joints"]);
    if (pose.contains("time") && !pose["time"].is_none()) inner.second = pose["time"].cast<double>();
    return inner;
  }
  if (py::isinstance<py::dict>(pose)) {
    for (const auto& [k, v] : pose.cast<py::dict>()) {
      if (!py::isinstance<py::str>(k)) throw board_error(fault::usage, "a pose's joint names are strings");
      try {
        joints.emplace_back(k.cast<std::string>(), v.cast<double>());
      } catch (const py::cast_error&) {
        throw board_error(fault::usage, k.cast<std::string>() + ": degrees must be a number");
      }
    }
    return {joints, std::nullopt};
  }
  if (!py::isinstance<py::str>(pose) && !py::hasattr(pose, "__fspath__"))
    throw board_error(fault::usage, "a pose is a dict {joint: degrees} or a pose file's path");
  const std::string path = path_of(pose);
  try {
    const auto p = rcb4::robot::load_pose(path, b.robot());
    std::optional<double> t;
    if (p.time) t = static_cast<double>(p.time->count()) / 1000.0;
    return {p.joints, t};
  } catch (const rcb4::robot::profile_error& e) {
    throw board_error(fault::usage, e.what());
  }
}

py::dict joints_dict(const std::vector<std::pair<std::string, double>>& joints) {
  py::dict d;
  for (const auto& [n, v] : joints) d[py::str(n)] = v;
  return d;
}

}  // namespace

void bind_robot(py::module_& m, py::class_<board>& cls) {
  cls.def(
         "capture",
         [](board& b) {
           const std::vector<std::optional<double>> a = unlocked([&] { return b.angles(); });
           py::dict d;
           for (std::size_t i = 0; i < a.size(); ++i)
             if (a[i]) d[py::str(b.robot().joints()[i].name)] = std::round(*a[i] * 100) / 100;
           return d;
         },
         "The pose the robot is in: {joint: degrees} for every joint that answers (save it with pyrcb4.save_pose).")
      .def(
          "play",
          [](board& b, const py::object& pose, std::optional<double> time, bool wait) {
            auto [joints, file_time] = pose_of(b, pose);
            const double t = time.value_or(file_time.value_or(1.0));
            const double takes = unlocked([&] { return b.move(joints, t); });
            if (wait) sleep_interruptible(takes);
            return takes;
          },
          "pose"_a, "time"_a = py::none(), "wait"_a = true,
          "Moves to a pose: a dict {joint: degrees} or a pose file (JSON/YAML, as rcb4 pose writes); time in "
          "seconds (default: the file's time_ms, else 1 s). Limits are checked before anything is sent.")
      .def(
          "trims",
          [](board& b, bool rom) {
            const auto ts = unlocked([&] { return b.trims(); });
            py::dict d;
            for (const auto& t : ts) {
              if (!t.allocated) continue;
              const auto deg = rom ? t.rom_degrees() : std::optional<double>(t.degrees());
              d[py::str(t.j->name)] =
                  deg ? py::object(py::float_(std::round(*deg * 100) / 100)) : py::object(py::none());
            }
            return d;
          },
          "rom"_a = false,
          "Every joint's trim in degrees (joints without a servo left out): what the board adds now, or with "
          "rom=True what power-on loads (None where the ROM has no copy).")
      .def(
          "set_trims",
          [](board& b, const py::dict& trims, bool persistent) {
            std::vector<std::pair<std::string, double>> ts;
            for (const auto& [k, v] : trims) {
              if (!py::isinstance<py::str>(k)) throw board_error(fault::usage, "trims: {joint name: degrees}");
              ts.emplace_back(k.cast<std::string>(), number_of(v, "trims"));
            }
            const auto r = unlocked([&] { return b.set_trims(ts, persistent); });
            py::dict out;
            for (const auto& t : r.written) out[py::str(t.j->name)] = t.counts;
            return out;
          },
          "trims"_a, "persistent"_a = false,
          "Sets trims {joint: degrees} (within ±30; LimitError beyond) and reads them back; persistent=True also "
          "writes them to ROM. Returns {joint: counts}.")
      .def(
          "servos",
          [](board& b) {
            const std::vector<rcb4::robot::joint_reading> rs = unlocked([&] { return b.states(); });
            py::dict d;
            for (const auto& r : rs)
              if (r.allocated)
                d[py::int_(r.j->ics.value())] =
                    py::dict("joint"_a = r.j->name, "position"_a = r.position, "target"_a = r.target, "trim"_a = r.trim,
                             "answered"_a = r.answered());
            return d;
          },
          "The joints' servo blocks by ICS number: joint, position (measured; 0: never answered), target (FREE "
          "0x8000, HOLD 0x7FFF), trim (counts), answered.")
      .def(
          "scan",
          [](board& b) {
            const std::vector<rcb4::ops::slot_probe> ps = unlocked([&] { return b.scan(); });
            py::list out;
            for (const auto& p : ps) {
              const auto* j = b.robot().on(p.ics);
              out.append(py::dict("ics"_a = p.ics.value(), "address"_a = p.address, "position"_a = p.position,
                                  "answers"_a = p.answers(),
                                  "joint"_a = j ? py::object(py::str(j->name)) : py::object(py::none())));
            }
            return out;
          },
          "The servo slots the board allocates, whether each answers, and the profile's joint on it.")
      .def(
          "move_servos",
          [](board& b, const py::dict& targets, unsigned frames) {
            rcb4::servo_set<rcb4::servo_position> set;
            // Numbers as Python has them: int, numpy integers (anything with __index__).
            const auto whole = [](const py::handle& h) -> std::optional<long long> {
              if (py::isinstance<py::str>(h) || py::isinstance<py::float_>(h) || py::isinstance<py::bool_>(h))
                return std::nullopt;
              try {
                return py::int_(py::reinterpret_borrow<py::object>(h)).cast<long long>();
              } catch (const py::error_already_set&) {
                return std::nullopt;
              } catch (const py::cast_error&) {
                return std::nullopt;
              }
            };
            for (const auto& [k, v] : targets) {
              const auto key = whole(k);
              if (!key || *key < 0 || *key > 35)
                throw board_error(fault::usage, "move_servos: an ICS number is a whole number 0..35");
              const auto ics = rcb4::ics_number::make(static_cast<unsigned>(*key));
              if (set.contains(*ics)) throw board_error(fault::usage, "move_servos: ICS given twice");
              std::optional<rcb4::servo_position> p;
              if (py::isinstance<py::str>(v)) {
                const auto w = v.cast<std::string>();
                if (w == "free") p = rcb4::servo_position::free();
                if (w == "hold") p = rcb4::servo_position::hold();
              } else if (const auto n = whole(v); n && *n >= 0 && *n <= 0x3FFF) {
                p = rcb4::servo_position::make(static_cast<int>(*n)).value();
              }
              if (!p) throw board_error(fault::usage, "move_servos: a position is 0..16383, 'free' or 'hold'");
              set.insert(*ics, *p);
            }
            py::gil_scoped_release release;
            b.move_servos(set, frames);
          },
          "targets"_a, "frames"_a = 1,
          "Servos by ICS number {ics: position} (0..16383, 'free', 'hold') in one CONST over frames output periods.")
      .def(
          "set_config",
          [](board& b, const py::kwargs& fields) {
            rcb4::config_word c = unlocked([&] { return b.config(); });
            for (const auto& [k, v] : fields) {
              const auto key = k.cast<std::string>();
              const auto flag = [&](bool& f) {
                if (!py::isinstance<py::bool_>(v)) throw board_error(fault::usage, key + ": True or False");
                f = v.cast<bool>();
              };
              if (key == "ics")
                flag(c.ics_enabled);
              else if (key == "program")
                flag(c.rom_program);
              else if (key == "interp_message")
                flag(c.interpolation_message);
              else if (key == "vector_jump")
                flag(c.vector_jump);
              else if (key == "led")
                flag(c.led);
              else if (key == "period_ms") {
                const auto ms = v.cast<int>();
                if (ms != 10 && ms != 15 && ms != 20 && ms != 25)
                  throw board_error(fault::usage, "period_ms: 10, 15, 20 or 25");
                c.period = static_cast<rcb4::output_period>((ms - 10) / 5);
              } else if (key == "ics_baud") {
                const auto code = rcb4::baud_code_of(v.cast<std::uint32_t>());
                if (!code) throw board_error(fault::usage, "ics_baud: 115200, 625000 or 1250000");
                c.ics_baud = *code;
              } else {
                throw board_error(fault::usage, "set_config: '" + key +
                                                    "' is not a field it writes (ics, program, interp_message, "
                                                    "vector_jump, period_ms, ics_baud, led; the COM baud: rcb4 config "
                                                    "set baud=)");
              }
            }
            py::gil_scoped_release release;
            b.set_config(c);
          },
          "Changes config fields (RAM: power-off restores): ics, program, interp_message, vector_jump, led (bool), "
          "period_ms (10/15/20/25), ics_baud.")
      .def(
          "control_loop", [](board& b) { return std::make_unique<control_loop>(b); }, py::keep_alive<0, 1>(),
          "A control loop over every joint: planned reads, one CONST per write (see ControlLoop).");

  py::class_<control_loop>(m, "ControlLoop", R"(The read and write halves of a control loop.

    loop = board.control_loop()
    while True:
        q = loop.read()                 # numpy, degrees, in board.joint_names order (NaN: no answer)
        loop.write(q + step, frames=1)  # one CONST of the targets given (NaN: that joint left out)

The reads are planned once for the link; nothing is allocated per cycle in C++.)")
      .def(
          "read",
          [](control_loop& l, const py::object& out) {
            // out is filled in place: anything that would need a copy (another dtype, a strided view,
            // a list) is refused rather than copied and left stale.
            py::array_t<double, py::array::c_style> a;
            if (out.is_none()) {
              a = py::array_t<double, py::array::c_style>(static_cast<py::ssize_t>(l.size()));
            } else {
              const auto arr = py::isinstance<py::array>(out) ? py::reinterpret_borrow<py::array>(out) : py::array();
              const bool fits = py::isinstance<py::array>(out) && arr.dtype().is(py::dtype::of<double>()) &&
                                (arr.flags() & py::array::c_style) != 0 && arr.writeable();
              if (!fits)
                throw board_error(fault::usage, "out: a writable, contiguous float64 numpy array of " +
                                                    std::to_string(l.size()) + " values");
              a = py::reinterpret_borrow<py::array_t<double, py::array::c_style>>(out);
            }
            if (a.ndim() != 1 || static_cast<std::size_t>(a.shape(0)) != l.size())
              throw board_error(fault::usage, "out: a float64 array of " + std::to_string(l.size()) + " values");
            double* p = a.mutable_data();
            {
              py::gil_scoped_release release;
              l.read(p);
            }
            return a;
          },
          "out"_a = py::none(), "Every joint's angle in degrees (into out when given: no new array).")
      .def(
          "write",
          [](control_loop& l, const py::array_t<double, py::array::c_style | py::array::forcecast>& targets,
             unsigned frames) {
            if (targets.ndim() != 1 || static_cast<std::size_t>(targets.shape(0)) != l.size())
              throw board_error(fault::usage,
                                "targets: " + std::to_string(l.size()) + " degrees, in joint_names order");
            if (const auto p = l.set(targets.data())) throw board_error(fault::limit, *p + " (nothing was sent)");
            py::gil_scoped_release release;
            l.send(frames);
          },
          "targets"_a, "frames"_a = 1,
          "Sends the targets (degrees; NaN leaves a joint out: it goes on to its earlier target) as one CONST "
          "reached in frames output periods; a target beyond a limit raises LimitError and sends nothing.")
      .def_property_readonly("size", &control_loop::size, "How many joints (the profile's).")
      .def_property_readonly(
          "plan",
          [](const control_loop& l) {
            std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
            for (const auto& r : l.plan()) out.emplace_back(r.address, r.size);
            return out;
          },
          "The RAM reads the planner chose for this link: (address, size) each.")
      .def_property_readonly("slots", &control_loop::slots, "The ICS numbers a write sends, ascending.");

  m.def(
      "move_refusal",
      [](const py::dict& state) -> std::optional<std::string> {
        rcb4::ops::motion_state st;
        st.running = state.contains("running") && state["running"].cast<bool>();
        if (state.contains("motion") && !state["motion"].is_none()) st.motion = state["motion"].cast<unsigned>();
        return rcb4::robot::services::move_refusal(st);
      },
      "state"_a,
      "Why a move must not be sent while the board is in @p state (a motion_status() dict): the words the tool, "
      "rcb4 ui and Board.move use; None when it may.");
  m.def(
      "load_pose",
      [](const py::object& path, const std::string& robot) {
        const std::string p = path_of(path);
        try {
          const auto model = rcb4::robot::open_profile(robot);
          const auto pose = rcb4::robot::load_pose(p, model);
          return py::dict("robot"_a = pose.robot, "joints"_a = joints_dict(pose.joints),
                          "time"_a = pose.time ? py::object(py::float_(static_cast<double>(pose.time->count()) / 1000))
                                               : py::object(py::none()));
        } catch (const rcb4::robot::profile_error& e) {
          throw board_error(fault::usage, e.what());
        }
      },
      "path"_a, "robot"_a = "khr-3hv", "Reads a pose file (JSON or YAML, as rcb4 pose writes): robot, joints, time.");
  m.def(
      "save_pose",
      [](const py::object& path, const py::dict& joints, const std::string& robot, std::optional<double> time) {
        const std::string p = path_of(path);
        try {
          const auto model = rcb4::robot::open_profile(robot);
          rcb4::robot::pose pose{model.name(), {}, std::nullopt};
          for (const auto& [k, v] : joints) {
            const auto name = k.cast<std::string>();
            if (!model.find(name))
              throw board_error(fault::usage, "no joint of " + model.name() + " is called '" + name + "'");
            pose.joints.emplace_back(name, v.cast<double>());
          }
          if (time) pose.time = std::chrono::milliseconds(std::llround(*time * 1000));
          rcb4::robot::save_pose(p, pose);
        } catch (const rcb4::robot::profile_error& e) {
          throw board_error(fault::usage, e.what());
        }
      },
      "path"_a, "joints"_a, "robot"_a = "khr-3hv", "time"_a = py::none(),
      "Writes a pose file (.json, .yaml or .yml) that rcb4 pose play and Board.play read.");
}

}  // namespace pyrcb4
