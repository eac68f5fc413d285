// pyrcb4: IcsServo, one KONDO ICS servo on its own line (a KONDO adapter in ICS mode, `rcb4 ics
// serve --pty`, or an in-process virtual servo), and ics_scan. The rules are the robot service's
// (rcb4/robot/services/ics.hpp), as `rcb4 ics` runs them: the same operations, the same refusals
// (raise_refusal: BoardRefused, UsageError, Timeout), the same backup names (ics-idN-STAMP.bin).
// The GIL is released while the line is used; one call at a time reaches the line.
// SPDX-License-Identifier: BSL-1.0
#include "common.hpp"

#include <rcb4/ics/virtual_servo.hpp>
#include <rcb4/robot/services/ics.hpp>
#include <rcb4/transport/ics_port.hpp>

#include <fmt/format.h>
#include <pybind11/stl.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

namespace pyrcb4 {
namespace {

namespace sv = rcb4::robot::services;
namespace ics = rcb4::ics;
namespace t = rcb4::transport;
using namespace pybind11::literals;

/** @p f(), its refusals and line failures as pyrcb4's exceptions ("@p what: ..."). */
template <class F>
auto translated(const std::string& what, F&& f) {
  try {
    return f();
  } catch (const sv::refused& e) {
    raise_refusal(e, what);
  } catch (const boost::system::system_error& e) {  // rcb4::transport::ics_port's (unplugged, server gone)
    raise(std::error_code(e.code()), what);
  } catch (const std::system_error& e) {
    raise(e.code(), what);
  }
}

/** The line: a port in ICS mode (or a pseudo-terminal), or an in-process virtual servo. */
class ics_line {
 public:
  /** Opens @p device ("" : one virtual servo, ID 0 at 115200, as `rcb4 ics` without --device) at @p baud. */
  ics_line(const std::string& device, std::uint32_t baud) {
    if (device.empty()) {
      virtual_ = std::make_unique<sv::ics_virtual_link>(ics::virtual_line({ics::virtual_servo{}}));
      virtual_->set_baud(baud);
      where_ = "the in-process virtual ICS servo, a simulation";
      return;
    }
    try {
      port_ = std::make_unique<t::ics_port>(device, baud);
    } catch (const boost::system::system_error& e) {
      raise(std::error_code(e.code()), device);
    }
    link_ = std::make_unique<sv::ics_port_link<t::ics_port>>(*port_);
    where_ = device;
  }
  /** The line as the service takes it. */
  sv::ics_link& get() { return virtual_ ? static_cast<sv::ics_link&>(*virtual_) : *link_; }
  /** What was opened. */
  const std::string& where() const noexcept { return where_; }

 private:
  std::unique_ptr<sv::ics_virtual_link> virtual_;
  std::unique_ptr<t::ics_port> port_;
  std::unique_ptr<sv::ics_link> link_;  // over port_: declared after it, gone before it
  std::string where_;
};

/** One servo found on its line; close() lets the line go. Calls may come from several threads: one at a time. */
class ics_device {
 public:
  ics_device(const std::string& device, std::optional<std::uint32_t> baud, std::optional<ics::servo_id> id,
             const sv::ics_options& o)
      : line_(std::make_unique<ics_line>(device, baud.value_or(115200))),
        servo_(std::make_unique<sv::ics_servo>(line_->get(), id, baud, o)) {}

  /** @p f(servo) for @p what, with the GIL released and the line to itself; closed: UsageError. */
  template <class F>
  auto run(const char* what, F&& f) {
    py::gil_scoped_release release;
    std::lock_guard lock(m_);
    if (!servo_) throw board_error(fault::closed, std::string(what) + ": the IcsServo is closed");
    return translated(what, [&] { return f(*servo_); });
  }
  /** Lets the line go (a call under way ends first); later calls raise UsageError. */
  void close() {
    py::gil_scoped_release release;
    std::lock_guard lock(m_);
    servo_.reset();
    line_.reset();
  }
  bool closed() {
    py::gil_scoped_release release;  // a call under way may hold the line a while (an EEPROM write: seconds)
    std::lock_guard lock(m_);
    return !servo_;
  }
  const std::string& where() const noexcept { return where_; }

 private:
  std::mutex m_;
  std::unique_ptr<ics_line> line_;
  std::unique_ptr<sv::ics_servo> servo_;
  std::string where_ = line_->where();
};

/** A whole number from Python (int, a whole float, a numpy integer; not bool), for @p what. */
long long whole_of(const py::handle& v, const std::string& what) {
  const double d = number_of(v, what);
  if (d != std::floor(d) || std::abs(d) > 1e15)
    throw board_error(fault::usage, what + " must be a whole number, not " + py::repr(v).cast<std::string>());
  return static_cast<long long>(d);
}

/** Seconds for a line's reply allowance, as milliseconds (more than 0, at most 600 s). */
std::chrono::milliseconds timeout_of(double seconds) {
  if (!(seconds > 0) || seconds > 600) throw board_error(fault::usage, "timeout: more than 0, at most 600 seconds");
  return std::chrono::milliseconds(static_cast<long long>(std::ceil(seconds * 1000)));
}

/** The device argument: None (or "") for the in-process servo, else a path. */
std::string device_of(const py::object& device) {
  if (device.is_none()) return {};
  if (!py::isinstance<py::str>(device) && !py::hasattr(device, "__fspath__"))
    throw board_error(fault::usage, "device: a serial port such as '/dev/ttyUSB0', or None (an in-process servo)");
  const auto path = path_of(device);
  if (path.empty()) throw board_error(fault::usage, "device: '' names no device (None is the in-process servo)");
  return path;
}

std::optional<std::uint32_t> baud_of(const py::object& baud) {
  if (baud.is_none()) return std::nullopt;
  const auto b = whole_of(baud, "baud");
  if (b <= 0 || b > 0xFFFFFFFFLL || !ics::baud_code(static_cast<std::uint32_t>(b)))
    throw board_error(fault::usage, fmt::format("baud {}: an ICS line runs at 115200, 625000 or 1250000", b));
  return static_cast<std::uint32_t>(b);
}

py::bytes bytes_of(const ics::eeprom_image& e) {
  return py::bytes(reinterpret_cast<const char*>(e.bytes().data()), e.bytes().size());
}

py::str name_of(const ics::field_info& i) { return py::str(i.name.data(), i.name.size()); }

/** A field's value as Python has it: flags as bool, the rest as int. */
py::object value_of(const ics::field_info& i, long v) {
  return i.nibbles == 0 ? py::object(py::bool_(v != 0)) : py::object(py::int_(v));
}

py::dict eeprom_dict(const ics::eeprom_image& e) {
  py::dict d;
  for (const auto& i : ics::fields) d[name_of(i)] = value_of(i, e.get(i.f));
  d["raw"] = bytes_of(e);
  return d;
}

py::dict report_dict(const sv::ics_eeprom_report& r) {
  py::dict changed;
  for (const auto& [f, v] : r.changed) changed[name_of(ics::info(f))] = value_of(ics::info(f), v);
  py::list notes;
  for (const auto& n : r.notes) notes.append(python_words(n));
  return py::dict("written"_a = r.written, "changed"_a = changed,
                  "backup"_a = r.backup.empty() ? py::object(py::none()) : py::object(py::str(r.backup)),
                  "notes"_a = notes);
}

py::dict position_dict(std::uint16_t counts) {
  return py::dict("counts"_a = counts, "degrees"_a = ics::position::degrees(counts));
}

/** "name=value" for parse_ics_setting from a keyword argument: flags True/False (or 1/0), numbers whole. */
std::string setting_text(const std::string& name, const py::handle& v) {
  if (!ics::find_field(name)) {
    std::string names;
    for (const auto& i : ics::fields)
      if (i.writable) names += fmt::format("{}{}", names.empty() ? "" : ", ", i.name);
    throw board_error(fault::usage, fmt::format("set: {}: no such field (the fields: {})", name, names));
  }
  const auto* inf = ics::find_field(name);
  if (py::isinstance<py::bool_>(v)) {
    if (inf->nibbles != 0)
      throw board_error(fault::usage, fmt::format("set: {}={}: a number, not True or False", name,
                                                  v.cast<bool>() ? "True" : "False"));
    return name + (v.cast<bool>() ? "=on" : "=off");
  }
  if (inf->nibbles == 0 && py::isinstance<py::str>(v))  // a flag takes the tool's words too: on/off, yes/no, true/false
    return name + "=" + v.cast<std::string>();
  return name + "=" + std::to_string(whole_of(v, "set: " + name));
}

std::unique_ptr<ics_device> open_servo(const py::object& device, const py::object& id, const py::object& baud,
                                       double timeout) {
  const auto path = device_of(device);
  std::optional<ics::servo_id> sid;
  if (!id.is_none()) {
    const auto n = whole_of(id, "id");
    const auto made = ics::servo_id::make(n);
    if (!made) throw board_error(fault::usage, fmt::format("id {}: an ICS servo ID is 0..31", n));
    sid = *made;
  }
  const auto b = baud_of(baud);
  sv::ics_options o;
  o.timeout = timeout_of(timeout);
  py::gil_scoped_release release;
  return translated("IcsServo", [&] { return std::make_unique<ics_device>(path, b, sid, o); });
}

/** A parameter (stretch, speed): read when @p value is None, else written live (1..127). */
std::uint8_t parameter(ics_device& d, const char* what, ics::sub s, const py::object& value) {
  if (value.is_none()) return d.run(what, [&](sv::ics_servo& servo) { return servo.read(s); });
  const auto v = whole_of(value, what);
  if (v < -1000 || v > 1000) throw board_error(fault::usage, fmt::format("{} {}: out of range 1..127", what, v));
  return d.run(what, [&](sv::ics_servo& servo) { return servo.write(s, static_cast<long>(v)); });
}

}  // namespace

void bind_ics(py::module_& m) {
  py::class_<ics_device> cls(m, "IcsServo", R"(One KONDO ICS servo on its own line.

IcsServo(device=None, id=None, baud=None, timeout=0.1)

device: None for an in-process virtual servo (ID 0 at 115200; every example runs without
hardware), or the serial port of a KONDO adapter in ICS mode ("/dev/ttyUSB0"), or the path
`rcb4 ics serve --pty` prints. id: the servo's ID (None: the one servo on the line, by the ID
command, which every device answers). baud: 115200, 625000 or 1250000 (None: each in turn,
115200 first). timeout: seconds to wait for a reply beyond its wire time. Finding the servo is
part of opening: Timeout when nothing answers, BoardRefused when more than one device answers
the ID read (give id) or the answer is garbled.

The rules are `rcb4 ics`'s: every EEPROM change starts from the servo's own image, read and
checked; the old image is saved before the first write; only the fields asked change (the
factory-correction bytes 25-26, 33-50, 55-56 are always written back as read); the image is
read back after a write. Use it as a context manager, or call close().)");
  cls.def(py::init(&open_servo), "device"_a = py::none(), "id"_a = py::none(), "baud"_a = py::none(), "timeout"_a = 0.1)
      .def(
          "__enter__",
          [](ics_device& d) -> ics_device& {
            if (d.closed()) throw board_error(fault::closed, "with: the IcsServo is closed");
            return d;
          },
          py::return_value_policy::reference)
      .def("__exit__", [](ics_device& d, const py::args&) { d.close(); })
      .def("close", &ics_device::close, "Lets the line go (the port is free again); later calls raise UsageError.")
      .def_property_readonly("closed", &ics_device::closed, "True after close().")
      .def_property_readonly("where", &ics_device::where, "What was opened.")
      .def_property_readonly(
          "id", [](ics_device& d) { return d.run("id", [](sv::ics_servo& s) { return s.id().value(); }); },
          "The servo's ID (as found, or as set_id() left it).")
      .def_property_readonly(
          "baud", [](ics_device& d) { return d.run("baud", [](sv::ics_servo& s) { return s.baud(); }); },
          "The rate it answers at (after set(baud=...), the new one).")
      .def(
          "__repr__",
          [](ics_device& d) {
            if (d.closed()) return "<pyrcb4.IcsServo " + d.where() + " (closed)>";
            const auto [id, baud] = d.run("repr", [](sv::ics_servo& s) { return std::pair{s.id().value(), s.baud()}; });
            return fmt::format("<pyrcb4.IcsServo ID {} at {} baud on {}>", id, baud, d.where());
          })
      .def(
          "read_id",
          [](ics_device& d) { return d.run("read_id", [](sv::ics_servo& s) { return s.read_id().value(); }); },
          "The ID the one device on the line answers the ID command with; BoardRefused when more than one answers.")
      .def(
          "set_id",
          [](ics_device& d, const py::object& n) {
            const auto v = whole_of(n, "set_id: n");
            const auto made = ics::servo_id::make(v);
            if (!made) throw board_error(fault::usage, fmt::format("set_id: {}: an ICS servo ID is 0..31", v));
            return d.run("set_id", [&](sv::ics_servo& s) { return s.set_id(*made).value(); });
          },
          "n"_a,
          "Gives the servo ID n (0..31) and returns it, read back. Only when it is alone on the line: checked first "
          "with the ID command (BoardRefused, nothing written, when more than one device answers or the one that "
          "answers is not this servo).")
      .def(
          "eeprom",
          [](ics_device& d) {
            const auto e = d.run("eeprom", [](sv::ics_servo& s) { return s.read_eeprom(); });
            return eeprom_dict(e);
          },
          "The EEPROM, read and checked, decoded: {field: value} with the names of `rcb4 ics set` (stretch, speed, "
          "punch, dead_band, damping, safe_timer, slave, rotation, pwm_inhibit, free, reverse, max_limit, min_limit, "
          "baud, temperature_limit, current_limit, response, user_offset, id, stretch_1..3), in ICS Manager's units "
          "(stretch 1..127, baud as the rate, limits in counts), flags as bool; raw: the 64 bytes.")
      .def(
          "eeprom_bytes",
          [](ics_device& d) {
            const auto e = d.run("eeprom_bytes", [](sv::ics_servo& s) { return s.read_eeprom(); });
            return bytes_of(e);
          },
          "The EEPROM's 64 bytes as read (each 0..15: one nibble a byte), checked.")
      .def(
          "backup",
          [](ics_device& d, const py::object& path, bool force) {
            const auto p = path_of(path);
            const auto [id, baud] = d.run("backup", [&](sv::ics_servo& s) {
              sv::save_ics_image(p, s.read_eeprom(), force);
              return std::pair{s.id().value(), s.baud()};
            });
            return py::dict("file"_a = p, "id"_a = id, "baud"_a = baud);
          },
          "path"_a, "force"_a = false,
          "Saves the servo's own 64 EEPROM bytes to path, as `rcb4 ics eeprom backup` does (UsageError when path "
          "exists, unless force=True); returns {file, id, baud}.")
      .def(
          "restore",
          [](ics_device& d, const py::object& path, bool force, const py::object& backup_dir) {
            const auto p = path_of(path);
            const auto dir = path_of(backup_dir);
            const auto r = d.run("restore", [&](sv::ics_servo& s) {
              const auto image = sv::load_ics_image(p);
              return s.restore(image, force, sv::ics_backup_in(dir, s.id()));
            });
            return report_dict(r);
          },
          "path"_a, "force"_a = false, "backup_dir"_a = ".",
          "Writes a backup (from backup() or `rcb4 ics eeprom backup`) back where it differs: the old image saved "
          "first to backup_dir/ics-idN-STAMP.bin, written, read back. BoardRefused, nothing written, when the backup "
          "is another servo's (its factory bytes differ) unless force=True; this servo's factory bytes and ID are "
          "kept in any case. Returns {written, changed (field: new value), backup (the file, or None when nothing "
          "differed), notes}.")
      .def(
          "set",
          [](ics_device& d, const py::object& backup_dir, bool force, const py::kwargs& fields) {
            const auto dir = path_of(backup_dir);
            if (fields.empty()) throw board_error(fault::usage, "set: give fields, e.g. set(stretch=40, speed=100)");
            std::vector<std::string> words;
            for (const auto& [k, v] : fields) words.push_back(setting_text(k.cast<std::string>(), v));
            std::vector<std::pair<ics::field, long>> changes;
            try {
              for (const auto& w : words) changes.push_back(sv::parse_ics_setting(w));  // before the line is used
            } catch (const sv::refused& e) {
              raise_refusal(e, "set");
            }
            const auto r = d.run(
                "set", [&](sv::ics_servo& s) { return s.set_fields(changes, sv::ics_backup_in(dir, s.id()), force); });
            return report_dict(r);
          },
          "backup_dir"_a = ".", "force"_a = false,
          "Changes EEPROM fields, e.g. set(stretch=40, speed=100, reverse=True): checked first (UsageError, nothing "
          "read or written, for an unknown field, id or free, or a value out of range), then read, the old image "
          "saved to backup_dir/ics-idN-STAMP.bin, written, read back. Returns {written, changed, backup, notes} as "
          "restore() does; set(baud=...) moves the line to the new rate (a note says so). slave=True (the servo "
          "never answers again) is refused unless force=True.")
      .def(
          "move",
          [](ics_device& d, const py::object& degrees, const py::object& counts) {
            if (degrees.is_none() == counts.is_none())
              throw board_error(fault::usage, "move: give degrees=... (-135..135) or counts=... (3500..11500)");
            std::uint16_t target = 0;
            if (!degrees.is_none()) {
              const double deg = number_of(degrees, "move: degrees");
              const auto c = ics::position::counts(deg);
              if (!c) throw board_error(fault::usage, fmt::format("move: {} degrees: out of range -135..135", deg));
              target = *c;
            } else {
              const auto c = whole_of(counts, "move: counts");
              if (c < 0 || c > 0xFFFF)
                throw board_error(fault::usage,
                                  fmt::format("move: position {}: out of range {}..{} (-135..135 degrees)", c,
                                              ics::position::min, ics::position::max));
              target = static_cast<std::uint16_t>(c);
            }
            const auto was = d.run("move", [&](sv::ics_servo& s) { return s.move(target); });
            auto r = position_dict(was);
            r["target"] = position_dict(target);
            return r;
          },
          "degrees"_a = py::none(), "counts"_a = py::none(),
          "Sends the servo to degrees (-135..135 from neutral) or counts (3500..11500, 7500 neutral) and returns "
          "where it stood as the command arrived: {counts, degrees, target: {counts, degrees}}. It does not wait: "
          "read position() (ICS 3.6) to see it arrive.")
      .def(
          "free",
          [](ics_device& d) {
            const auto was = d.run("free", [](sv::ics_servo& s) { return s.free(); });
            return position_dict(was);
          },
          "Makes the servo go limp; returns where it stopped holding: {counts, degrees}.")
      .def(
          "position",
          [](ics_device& d) {
            const auto c = d.run("position", [](sv::ics_servo& s) { return s.position(); });
            return ics::position::degrees(c);
          },
          "Where it stands, in degrees from neutral (the ICS 3.6 position read; BoardRefused from an ICS 3.5 servo, "
          "which tells its position only in reply to move() or free()).")
      .def(
          "position_counts",
          [](ics_device& d) { return d.run("position_counts", [](sv::ics_servo& s) { return s.position(); }); },
          "Where it stands, in counts (7500 neutral, 4000 counts a 135 degrees), as position() reads it.")
      .def(
          "stretch",
          [](ics_device& d, const py::object& value) { return parameter(d, "stretch", ics::sub::stretch, value); },
          "value"_a = py::none(),
          "The stretch (holding stiffness, 1..127): read, or with value set live (the EEPROM keeps its own: "
          "set(stretch=...)); returns the value.")
      .def(
          "speed", [](ics_device& d, const py::object& value) { return parameter(d, "speed", ics::sub::speed, value); },
          "value"_a = py::none(),
          "The speed (1..127, 127 the fastest): read, or with value set live (the EEPROM keeps its own: "
          "set(speed=...)); returns the value.")
      .def(
          "current",
          [](ics_device& d) { return d.run("current", [](sv::ics_servo& s) { return s.read(ics::sub::current); }); },
          "The current it draws, 0..127: the low 6 bits about 0.1 A a unit, bit 6 the direction.")
      .def(
          "temperature",
          [](ics_device& d) {
            return d.run("temperature", [](sv::ics_servo& s) { return s.read(ics::sub::temperature); });
          },
          "Its temperature value, 1..127: smaller is hotter (KONDO's scales to degrees disagree: docs/ics-servos.md).");

  m.def(
      "ics_scan",
      [](const py::object& device, const py::object& bauds, double timeout) {
        const auto path = device_of(device);
        std::vector<std::uint32_t> rates;
        if (!bauds.is_none()) {
          if (py::isinstance<py::str>(bauds) || !py::isinstance<py::iterable>(bauds))
            throw board_error(fault::usage, "bauds: a list of rates (115200, 625000, 1250000), or None for all three");
          for (const auto& b : bauds) {
            const auto v = whole_of(b, "bauds");
            if (v <= 0 || v > 0xFFFFFFFFLL)
              throw board_error(fault::usage, fmt::format("baud {}: an ICS line runs at 115200, 625000 or 1250000", v));
            rates.push_back(static_cast<std::uint32_t>(v));
          }
        }
        sv::ics_options o;
        o.timeout = timeout_of(timeout);
        struct interrupted {};
        std::vector<sv::ics_found> found;
        try {
          py::gil_scoped_release release;
          found = translated("ics_scan", [&] {
            ics_line line(path, 115200);
            return sv::ics_scan(line.get(), rates, o, [](std::uint32_t) {
              py::gil_scoped_acquire acquire;
              if (PyErr_CheckSignals() != 0) throw interrupted{};  // Ctrl-C, looked at each rate
            });
          });
        } catch (const interrupted&) {
          throw py::error_already_set();
        }
        py::list out;
        for (const auto& f : found) {
          const bool bad = !f.problem.empty();
          out.append(py::dict("id"_a = f.id.value(), "baud"_a = f.baud,
                              "ics"_a = bad ? py::object(py::none()) : py::object(py::str(f.ics36 ? "3.6" : "3.5")),
                              "stretch"_a = bad ? py::object(py::none()) : py::object(py::int_(f.stretch)),
                              "speed"_a = bad ? py::object(py::none()) : py::object(py::int_(f.speed)),
                              "problem"_a = bad ? py::object(py::str(f.problem)) : py::object(py::none())));
        }
        return out;
      },
      "device"_a = py::none(), "bauds"_a = py::none(), "timeout"_a = 0.03,
      "Every ICS servo on the line (device as IcsServo takes it; None: the in-process servo): at each rate of bauds "
      "(None: 115200, 625000, 1250000) where anything answers the ID read, every ID 0..31 asked its stretch and speed "
      "(which changes nothing), timeout seconds each. Returns [{id, baud, ics ('3.6', or '3.5': no position read), "
      "stretch, speed, problem}]: problem is None, or why an ID answered wrongly (garbled; then ics, stretch and speed "
      "are None). An empty list: nothing answered.");
}

}  // namespace pyrcb4
