// pyrcb4: the Python module (pybind11). The Board of board.hpp with Python's names and types; the
// GIL is released while the wire is used, waits check for Ctrl-C every 50 ms, and every failure
// is one of the module's exceptions, whose message is the C++ one.
// SPDX-License-Identifier: BSL-1.0
#include "common.hpp"

#include <cstdlib>
#include <map>

#include <rcb4/robot/services/motion_slots.hpp>
#include <rcb4/robot/services/slot_names.hpp>
#include <rcb4/robot/urdf.hpp>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <thread>

namespace py = pybind11;
using namespace pybind11::literals;

namespace pyrcb4 {
namespace {

/** The module's exception classes, kept for the life of the interpreter. */
struct exceptions {
  PyObject* error = nullptr;
  PyObject* refused = nullptr;
  PyObject* timeout = nullptr;
  PyObject* device = nullptr;
  PyObject* bad_reply = nullptr;
  PyObject* limit = nullptr;
  PyObject* usage = nullptr;
} exc;

PyObject* make_exception(py::module_& m, const char* name, py::tuple bases, const char* doc) {
  const std::string full = std::string("pyrcb4.") + name;
  PyObject* t = PyErr_NewExceptionWithDoc(full.c_str(), doc, bases.ptr(), nullptr);
  if (!t) throw py::error_already_set();
  m.attr(name) = py::reinterpret_borrow<py::object>(t);
  return t;  // the new reference stays with us: the class lives as long as the interpreter
}

PyObject* class_of(fault k) {
  switch (k) {
    case fault::refused: return exc.refused;
    case fault::timeout: return exc.timeout;
    case fault::device: return exc.device;
    case fault::bad_reply: return exc.bad_reply;
    case fault::limit: return exc.limit;
    case fault::usage:
    case fault::closed: return exc.usage;
  }
  return exc.error;
}

py::dict config_dict(const rcb4::config_word& c) {
  return py::dict("word"_a = c.encode(), "ics"_a = c.ics_enabled, "program"_a = c.rom_program,
                  "interp_message"_a = c.interpolation_message, "vector_jump"_a = c.vector_jump,
                  "period_ms"_a = rcb4::milliseconds(c.period), "baud"_a = rcb4::bits_per_second(c.com_baud),
                  "zero"_a = c.zero_flag, "carry"_a = c.carry_flag, "program_error"_a = c.program_error,
                  "ics_baud"_a = rcb4::bits_per_second(c.ics_baud), "led"_a = c.led);
}

py::dict status_dict(const motion_status& s) {
  return py::dict("running"_a = s.running, "suspended"_a = s.suspended,
                  "motion"_a = s.motion ? py::object(py::int_(*s.motion)) : py::object(py::none()),
                  "program_counter"_a = s.program_counter, "program_on"_a = s.program_on);
}

/** The slot names kept for @p b's robot (a names file that does not read: UsageError). */
std::map<unsigned, rcb4::robot::services::slot_label> load_names(const board& b) {
  try {
    return rcb4::robot::services::load_slot_labels(b.robot().name());
  } catch (const rcb4::robot::services::refused& e) {
    throw board_error(fault::usage, e.what());
  }
}

std::unique_ptr<board> open_board(const py::object& device, const py::object& baud, const std::string& robot,
                                  double timeout) {
  if (!(timeout > 0) || timeout > 600) throw board_error(fault::usage, "timeout: more than 0, at most 600 seconds");
  std::string path;
  if (!device.is_none()) {
    if (!py::isinstance<py::str>(device) && !py::hasattr(device, "__fspath__"))
      throw board_error(fault::usage, "device: a path such as '/dev/ttyUSB0', 'tcp:HOST:PORT', or None");
    path = path_of(device);
    if (path.empty()) throw board_error(fault::usage, "device: '' names no device (None is the virtual board)");
  } else if (const char* env = std::getenv("RCB4_DEVICE")) {  // as the rcb4 tool takes it
    if (!*env) throw board_error(fault::usage, "RCB4_DEVICE is set but empty (unset it for the virtual board)");
    path = env;
  } else {
    // Said once per process: a script that meant a robot learns it drives a simulation.
    static bool said = false;
    if (!said) {
      said = true;
      PySys_WriteStderr("pyrcb4: no device given (and no $RCB4_DEVICE): an in-process virtual board, a simulation\n");
    }
  }
  const std::uint32_t b = baud.is_none() ? 0u : baud.cast<std::uint32_t>();
  const auto ms = std::chrono::milliseconds(static_cast<long long>(std::ceil(timeout * 1000)));
  py::gil_scoped_release release;
  return std::make_unique<board>(path, b, robot, ms);
}

}  // namespace
}  // namespace pyrcb4

PYBIND11_MODULE(_core, m) {
  using namespace pyrcb4;
  m.doc() = "rcb4 for Python: KONDO's RCB-4 robot controller (KHR-3HV, KXR) over its serial line";
  m.attr("__version__") = RCB4_VERSION;

  exc.error = make_exception(m, "Error", py::make_tuple(py::handle(PyExc_Exception)), "Every pyrcb4 failure.");
  exc.refused = make_exception(m, "BoardRefused", py::make_tuple(py::handle(exc.error)),
                               "The board refused (NACK), or lacks what the call needs.");
  exc.timeout = make_exception(m, "Timeout", py::make_tuple(py::handle(exc.error), py::handle(PyExc_TimeoutError)),
                               "No answer before the deadline (a silent board, a wrong baud).");
  exc.device = make_exception(m, "DeviceError", py::make_tuple(py::handle(exc.error), py::handle(PyExc_OSError)),
                              "The device: no such port, busy, no permission, unplugged.");
  exc.bad_reply = make_exception(m, "BadReply", py::make_tuple(py::handle(exc.error)),
                                 "A malformed answer: checksum, length, another command's reply.");
  exc.limit = make_exception(m, "LimitError", py::make_tuple(py::handle(exc.error), py::handle(PyExc_ValueError)),
                             "A target beyond a joint's limit: nothing was sent.");
  exc.usage = make_exception(m, "UsageError", py::make_tuple(py::handle(exc.error), py::handle(PyExc_ValueError)),
                             "A call that can never work: an unknown joint, a bad argument, a closed board.");
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const board_error& e) {
      if (e.kind == fault::device && e.err != 0) {
        // An OSError with its errno and strerror, as open() raises one.
        py::tuple args = py::make_tuple(e.err, std::string(e.what()));
        PyErr_SetObject(class_of(e.kind), args.ptr());
      } else {
        PyErr_SetString(class_of(e.kind), e.what());
      }
    }
  });

  py::class_<board> cls(m, "Board", R"(An RCB-4 board.

Board(device=None, baud=None, robot="khr-3hv", timeout=0.1)

device: None for an in-process virtual board (every example runs without hardware), a serial
port ("/dev/ttyUSB0"), or "tcp:HOST:PORT" for a bridge. baud: 115200, 625000 or 1250000;
None detects it on a serial port. robot: a built-in profile ("khr-3hv", "kxr-l2") or a profile
file. timeout: seconds each exchange may take. Use it as a context manager, or call close().)");
  cls.def(py::init(&open_board), "device"_a = py::none(), "baud"_a = py::none(), "robot"_a = "khr-3hv",
          "timeout"_a = 0.1)
      .def(
          "__enter__",
          [](board& b) -> board& {
            if (!b.is_open()) throw board_error(fault::closed, "with: the board is closed");
            return b;
          },
          py::return_value_policy::reference)
      .def("__exit__",
           [](board& b, const py::args&) {
             py::gil_scoped_release release;
             b.close();
           })
      .def("close", &board::close, py::call_guard<py::gil_scoped_release>(),
           "Lets the line go (waits for calls under way); later calls raise UsageError.")
      .def_property_readonly(
          "closed", [](const board& b) { return !b.is_open(); }, "True after close().")
      .def_property_readonly("where", &board::where, "What was opened.")
      .def_property_readonly(
          "baud", &board::baud,
          "The line rate in use; None over TCP when no baud was given (the bridge's rate is its own).")
      .def("__repr__",
           [](const board& b) { return "<pyrcb4.Board " + b.where() + (b.is_open() ? "" : " (closed)") + ">"; })
      .def("ping", &board::ping, py::call_guard<py::gil_scoped_release>(), "One round trip; its time in seconds.")
      .def("version", &board::version, py::call_guard<py::gil_scoped_release>(), "The board's VERSION text.")
      .def_property_readonly(
          "config",
          [](board& b) {
            const rcb4::config_word c = unlocked([&] { return b.config(); });
            return config_dict(c);
          },
          "The config register at RAM 0x0000, decoded (a dict).")
      .def(
          "read",
          [](board& b, std::uint32_t address, std::size_t n, const std::string& memory) {
            std::vector<std::uint8_t> v;
            if (n > 0) {
              py::gil_scoped_release release;
              v = b.read(memory, address, n);
            }
            return py::bytes(reinterpret_cast<const char*>(v.data()), v.size());
          },
          "address"_a, "n"_a, "memory"_a = "ram", "n bytes of RAM or ROM from address, as bytes.")
      .def(
          "write",
          [](board& b, std::uint32_t address, const py::buffer& data, const std::string& memory) {
            // Anything with the buffer protocol: bytes, bytearray, memoryview, a numpy uint8 array.
            const py::buffer_info info = data.request();
            if (info.itemsize != 1 || info.ndim > 1)
              throw board_error(fault::usage, "write: data is bytes (or a 1-D buffer of bytes)");
            const auto* p = static_cast<const std::uint8_t*>(info.ptr);
            const std::vector<std::uint8_t> v(p, p + info.size);
            py::gil_scoped_release release;
            b.write(memory, address, v);
          },
          "address"_a, "data"_a, "memory"_a = "ram", "Writes bytes to RAM or ROM at address.")
      .def_property_readonly(
          "joint_names",
          [](const board& b) {
            std::vector<std::string> out;
            for (const auto& j : b.robot().joints()) out.push_back(j.name);
            return out;
          },
          "The profile's joints, in the order of angle_vector().")
      .def_property_readonly(
          "joint_limits",
          [](const board& b) {
            py::dict d;
            for (const auto& j : b.robot().joints()) d[py::str(j.name)] = py::make_tuple(j.lower, j.upper);
            return d;
          },
          "Each joint's (lower, upper) limit in degrees, from the profile: what move() and write() enforce.")
      .def_property_readonly(
          "mimic_joints",
          [](const board& b) {
            py::dict d;
            for (const auto& mj : b.robot().mimics())
              d[py::str(mj.name)] = py::make_tuple(mj.joint, mj.multiplier, mj.offset);
            return d;
          },
          "The profile's joints that follow another (URDF's mimic: no servo of their own): name -> (joint, "
          "multiplier, offset in degrees); the angle is multiplier × the joint's + offset.")
      .def(
          "urdf",
          [](const board& b, const std::string& prefix) {
            try {
              return rcb4::robot::to_urdf(b.robot(), {.prefix = prefix});
            } catch (const rcb4::robot::profile_error& e) {
              throw board_error(fault::usage, std::string("urdf: ") + e.what());
            }
          },
          "prefix"_a = "",
          "The robot as URDF (as rcb4 urdf writes it: joint names with prefix, limits, axes, simple geometry), for "
          "robot_description; UsageError when the profile has no kinematics.")
      .def_property_readonly(
          "period",
          [](board& b) {
            const rcb4::config_word c = unlocked([&] { return b.config(); });
            return rcb4::milliseconds(c.period) / 1000.0;
          },
          "The board's output period in seconds (one interpolation frame).")
      .def(
          "joints",
          [](board& b) {
            const std::vector<std::optional<double>> a = unlocked([&] { return b.angles(); });
            py::dict d;
            for (std::size_t i = 0; i < a.size(); ++i)
              d[py::str(b.robot().joints()[i].name)] = a[i] ? py::object(py::float_(*a[i])) : py::object(py::none());
            return d;
          },
          "Every joint's measured angle in degrees (None: its servo never answered, or it has none).")
      .def(
          "angle_vector",
          [](board& b) {
            const std::vector<std::optional<double>> a = unlocked([&] { return b.angles(); });
            py::array_t<double> out(static_cast<py::ssize_t>(a.size()));
            auto w = out.mutable_unchecked<1>();
            for (std::size_t i = 0; i < a.size(); ++i)
              w(static_cast<py::ssize_t>(i)) = a[i] ? *a[i] : std::numeric_limits<double>::quiet_NaN();
            return out;
          },
          "The joints' angles in degrees as a numpy array in joint_names order (NaN: no answer).")
      .def(
          "move",
          [](board& b, const py::dict& targets, double time, bool wait) {
            std::vector<std::pair<std::string, double>> ts;
            for (const auto& [k, v] : targets) {
              if (!py::isinstance<py::str>(k)) throw board_error(fault::usage, "move: joint names are strings");
              ts.emplace_back(k.cast<std::string>(), number_of(v, "move: " + k.cast<std::string>() + ": degrees"));
            }
            const double takes = unlocked([&] { return b.move(ts, time); });
            if (wait) sleep_interruptible(takes);
            return takes;
          },
          "targets"_a, "time"_a = 0.5, "wait"_a = true,
          "Moves joints {name: degrees} over time seconds; every limit is checked before anything is sent "
          "(LimitError names the joint). Returns the seconds the move takes; wait=True waits for them. A freed joint "
          "is moved too: a position is torque on (the board has no other way to move it; iory/rcb4 drops it instead).")
      .def(
          "free",
          [](board& b, const py::args& names) {
            const auto n = names_of(names);
            py::gil_scoped_release release;
            return b.power(true, n);
          },
          "Torque off for joints or groups (none: all); returns the joints freed.")
      .def(
          "hold",
          [](board& b, const py::args& names) {
            const auto n = names_of(names);
            py::gil_scoped_release release;
            return b.power(false, n);
          },
          "Torque on where they are, for joints or groups (none: all); returns the joints held.")
      .def(
          "play_motion",
          [](board& b, unsigned n, bool wait, double timeout) {
            {
              py::gil_scoped_release release;
              b.play_motion(n);
            }
            if (!wait) return py::object(py::none());
            py::gil_scoped_release release;
            const auto st = b.wait_motion(timeout, [] {
              py::gil_scoped_acquire acquire;
              check_signals();
            });
            py::gil_scoped_acquire acquire;
            return py::object(status_dict(st));
          },
          "n"_a, "wait"_a = true, "timeout"_a = 60.0,
          "Plays ROM motion n; wait=True waits until it ends (Ctrl-C interrupts the wait) and returns the state.")
      .def("stop_motion", &board::stop_motion, py::call_guard<py::gil_scoped_release>(),
           "Suspends the ROM program (resume_motion() continues it).")
      .def("resume_motion", &board::resume_motion, py::call_guard<py::gil_scoped_release>(),
           "Lets the ROM program run again where stop_motion() left it (a motion stopped part way goes on).")
      .def(
          "stretch",
          [](board& b, const py::object& value, const py::args& names) {
            const auto v = number_of(value, "stretch");
            if (v != std::floor(v)) throw board_error(fault::usage, "stretch: a whole number 1..127");
            const auto n = names_of(names);
            py::gil_scoped_release release;
            return b.set_param(false, static_cast<long long>(v), n);
          },
          "value"_a,
          "Sets the ICS stretch (holding stiffness, 1..127; 127 the stiffest) of joints or groups (none: all); returns "
          "the joints set. The board cannot read it back.")
      .def(
          "speed",
          [](board& b, const py::object& value, const py::args& names) {
            const auto v = number_of(value, "speed");
            if (v != std::floor(v)) throw board_error(fault::usage, "speed: a whole number 1..127");
            const auto n = names_of(names);
            py::gil_scoped_release release;
            return b.set_param(true, static_cast<long long>(v), n);
          },
          "value"_a,
          "Sets the ICS speed (output limit, 1..127; 127 the fastest) of joints or groups (none: all); returns the "
          "joints set. Not a move's time: that is move(time=...).")
      .def(
          "motion_status",
          [](board& b) {
            const motion_status st = unlocked([&] { return b.motion(); });
            return status_dict(st);
          },
          "Whether a motion runs: running, suspended, motion (or None), program_counter, program_on (the ROM program "
          "runs: off after stop_motion() or rom_restore(), when buttons play nothing until resume_motion()).")
      .def(
          "wait_motion",
          [](board& b, double timeout) {
            motion_status st;
            {
              py::gil_scoped_release release;
              st = b.wait_motion(timeout, [] {
                py::gil_scoped_acquire acquire;
                check_signals();
              });
            }
            return status_dict(st);
          },
          "timeout"_a = 60.0, "Waits until no motion runs (Timeout after timeout seconds).")
      .def(
          "motions",
          [](board& b) {
            const std::vector<rcb4::ops::motion_slot> v = unlocked([&] { return b.motions(); });
            const auto period = unlocked([&] { return b.period(); });
            const auto& layout = unlocked([&]() -> const rcb4::rom_layout& { return b.rom_layout(); });
            const auto names = load_names(b);
            py::list out;
            const auto states = rcb4::robot::services::slot_states(v, layout);
            for (std::size_t i = 0; i < v.size(); ++i) {
              const auto& s = v[i];
              const auto& state = states[i];
              const auto name = rcb4::robot::services::slot_name(b.robot(), s.number, names, s.code);
              // Its seconds as the board plays it (loops counted, no button held), where the steps express it.
              py::object seconds = py::none();
              if (const auto& t = state.plays) {
                if (const auto secs = rcb4::robot::services::play_seconds(*t, period))
                  seconds = py::float_(*secs);
                else if (t->endless)
                  seconds = py::float_(std::numeric_limits<double>::infinity());
              }
              out.append(py::dict(
                  "slot"_a = s.number,
                  "name"_a = name.empty() ? py::object(py::none()) : py::object(py::str(std::string(name))),
                  "address"_a = s.address, "size"_a = s.size, "frames"_a = s.frames, "seconds"_a = seconds,
                  "ends"_a = s.ends, "readable"_a = s.readable, "endless"_a = state.endless,
                  "broken"_a = !state.problem.empty(),
                  "problem"_a = state.problem.empty() ? py::object(py::none()) : py::object(py::str(state.problem))));
            }
            return out;
          },
          "The used motion slots in ROM: slot, name (the slot's name, kept when a motion file with a name is pushed; "
          "else the profile's), address, size, frames (the protocol's commands walked to the first RETURN), seconds "
          "(as the board plays it, loops counted; inf: for ever; None: it calls other motions or is not steps), "
          "ends (a RETURN reached), readable, endless (a loop with no way out), broken and problem (why a play would "
          "stop the board's program: a bad frame, no way out, a call of an empty or broken slot; else None).")
      .def(
          "sensors",
          [](board& b) {
            const sensor_reading s = unlocked([&] { return b.sensors(); });
            std::vector<double> volts;
            for (const auto v : s.ad) volts.push_back(std::round(v * 5.0 / 1024 * 1000) / 1000);
            return py::dict("battery_volts"_a = s.battery_volts, "ad"_a = s.ad, "ad_volts"_a = volts,
                            "pio_direction"_a = s.pio_direction, "pio_value"_a = s.pio_value, "buttons"_a = s.buttons,
                            "button_names"_a = s.button_names, "pa"_a = s.pa);
          },
          "battery_volts, ad (AD0..AD10 as read), ad_volts (each x 5 V / 1024: the 10-bit 0-5 V input; AD0 is the "
          "supply divided by 5), pio_direction, pio_value, buttons, button_names, pa (PA1..PA4).");
  bind_robot(m, cls);
  bind_services(cls);
  bind_ics(m);
}
