// pyrcb4: the robot services on Board, bound to Python: motion slots (show, pull, push, erase),
// the remote's buttons (read, set, clear, press, release), the whole ROM (backup, restore). The
// rules are the library's (rcb4/robot/services/): the same refusals as the rcb4 tool, as
// BoardRefused, UsageError and LimitError.
// SPDX-License-Identifier: BSL-1.0
#include "common.hpp"

#include <rcb4/fmt.hpp>
#include <rcb4/motion/buttons.hpp>
#include <rcb4/robot/motion_file.hpp>

#include <pybind11/stl.h>

#include <filesystem>
#include <fstream>

namespace pyrcb4 {
namespace sv = rcb4::robot::services;
namespace mo = rcb4::motion;
using namespace pybind11::literals;

namespace {

/** A button word from "s1+up" or an int. */
std::uint16_t button_word(const py::object& buttons) {
  if (py::isinstance<py::bool_>(buttons)) throw board_error(fault::usage, "buttons: a name such as 's1+up', or a word");
  if (py::isinstance<py::int_>(buttons)) {
    const auto v = buttons.cast<long long>();
    if (v < 1 || v > 0xFFFF || (v & ~rcb4::krr::valid_buttons))
      throw board_error(fault::usage, "buttons: " + std::to_string(v) + " is not a button word");
    return static_cast<std::uint16_t>(v);
  }
  if (!py::isinstance<py::str>(buttons)) throw board_error(fault::usage, "buttons: a name such as 's1+up', or a word");
  const auto b = mo::parse_buttons(buttons.cast<std::string>());
  if (!mo::ok(b)) throw board_error(fault::usage, "buttons: " + std::get<mo::failure>(b).message);
  return std::get<std::uint16_t>(b);
}

/** A motion file to write (.yaml or .yml), checked before the board is asked; empty for None. */
std::string motion_file_path(const py::object& path, bool force) {
  if (path.is_none()) return {};
  auto p = path_of(path);
  const auto ext = std::filesystem::path(p).extension();
  if (ext != ".yaml" && ext != ".yml") throw board_error(fault::usage, "path: " + p + " does not end in .yaml or .yml");
  if (std::filesystem::exists(p) && !force)
    throw board_error(fault::usage, "path: " + p + " exists (force=True replaces it)");
  return p;
}

/** A motion number, checked before anything is read. */
unsigned motion_number(long long n) {
  if (n < 1 || n > 120) throw board_error(fault::usage, "motion " + std::to_string(n) + " is outside 1..120");
  return static_cast<unsigned>(n);
}

/** A motion document as Python data: {"robot", "name", "period_ms", "steps": [...]}, as a motion file says it. */
py::object document_data(const rcb4::robot::motion_document& d) {
  return py::module_::import("json").attr("loads")(rcb4::robot::motion_json(d));
}

py::list entries_data(const std::vector<rcb4::vector_entry>& entries, const rcb4::rom_layout& layout) {
  py::list out;
  for (const auto& e : entries) {
    const auto b = e.buttons();
    const std::uint32_t a = e.target.value(), base = layout.motion_base.value();
    const bool slot =
        a >= base && (a - base) % layout.slot_size == 0 && (a - base) / layout.slot_size < layout.motion_count;
    out.append(
        py::dict("buttons"_a = b ? py::object(py::str(mo::buttons_text(*b))) : py::object(py::none()),
                 "button_word"_a = b ? py::object(py::int_(*b)) : py::object(py::none()),
                 "action"_a = e.action == rcb4::vector_action::call ? "call" : "jump", "address"_a = a,
                 "motion"_a = slot ? py::object(py::int_((a - base) / layout.slot_size + 1)) : py::object(py::none())));
  }
  return out;
}

py::dict table_data(const sv::table_report& r, const rcb4::rom_layout& layout) {
  return py::dict("done"_a = r.done, "entries"_a = entries_data(r.entries, layout),
                  "ram_followed_rom"_a = r.ram_followed_rom);
}

/** What push_motion and play_motion_file take: a motion file, a .bin backup, or steps as data. */
sv::push_source source_of(board& b, const py::object& what) {
  sv::push_source src;
  if (py::isinstance<py::list>(what) || py::isinstance<py::dict>(what)) {
    // Steps as data (a list, or the dict pull_motion gives): JSON is YAML, so the motion-file parser reads
    // them.
    py::dict doc;
    if (py::isinstance<py::dict>(what)) {
      for (const auto& kv : what.cast<py::dict>()) {
        const auto key = kv.first.cast<std::string>();
        if (key == "robot" || key == "name" || key == "period_ms" || key == "steps") doc[kv.first] = kv.second;
      }
    } else {
      doc["steps"] = what;
    }
    if (!doc.contains("robot")) doc["robot"] = b.robot().name();
    if (!doc.contains("period_ms"))  // times in ms of this board's period
      doc["period_ms"] = rcb4::milliseconds(unlocked([&] { return b.period(); }));
    const auto text = py::module_::import("json").attr("dumps")(doc).cast<std::string>();
    try {
      src.document = rcb4::robot::parse_motion(text, "steps", b.robot());
    } catch (const rcb4::robot::profile_error& e) {
      throw board_error(fault::usage, e.what());
    }
    src.name = "steps";
  } else {
    const auto p = path_of(what);
    src.name = p;
    if (std::filesystem::path(p).extension() == ".bin") {
      try {
        src.bin = sv::read_backup_file(p);
      } catch (const sv::refused& e) {
        throw board_error(fault::usage, e.what());
      }
    } else {
      try {
        src.document = rcb4::robot::load_motion(p, b.robot());
      } catch (const rcb4::robot::profile_error& e) {
        throw board_error(fault::usage, e.what());
      }
    }
  }
  return src;
}

}  // namespace

void bind_services(py::class_<board>& cls) {
  cls.def(
         "show_motion",
         [](board& b, long long n) {
           const auto k = motion_number(n);
           auto [bytes, code] = unlocked([&] { return b.show_motion(k); });
           py::list listing;
           for (const auto& in : code.code)
             listing.append(py::dict("address"_a = in.address, "hex"_a = fmt::format("{}", rcb4::hex_view{in.bytes}),
                                     "text"_a = in.cmd ? fmt::format("{}", *in.cmd) : std::string("(not a frame)")));
           const bool empty = bytes.empty() || bytes[0] == 0xFF;
           return py::dict("motion"_a = k, "address"_a = code.where.address.value(), "empty"_a = empty,
                           "code"_a = empty ? py::list() : listing,
                           "problems"_a = empty ? std::vector<std::string>{} : code.problems, "notes"_a = code.notes,
                           "calls"_a = code.calls);
         },
         "n"_a,
         "Motion n's code as the board runs it: code (address, hex, text of each frame), problems (what stops the "
         "board), notes, calls (the addresses it calls); empty for erased ROM.")
      .def(
          "pull_motion",
          [](board& b, long long n, const py::object& path, bool force) {
            const auto k = motion_number(n);
            const auto p = motion_file_path(path, force);
            const auto r = unlocked([&] { return b.pull_motion(k); });
            if (!p.empty()) {
              try {
                rcb4::robot::save_motion(p, r.document,
                                         fmt::format("motion {} of the board (0x{:06X}, {} layout), pulled by pyrcb4",
                                                     k, r.address, r.layout));
              } catch (const rcb4::robot::profile_error& e) {
                throw board_error(fault::usage, e.what());
              }
            }
            auto d = document_data(r.document);
            d["motion"] = k;
            d["address"] = r.address;
            d["bytes"] = r.bytes;
            d["poses"] = r.poses;
            d["beyond"] = r.beyond.empty() ? py::object(py::none()) : py::object(py::str(r.beyond));
            d["file"] = p.empty() ? py::object(py::none()) : py::object(py::str(p));
            return d;
          },
          "n"_a, "path"_a = py::none(), "force"_a = false,
          "Motion n as a motion file says it: {robot, name, period_ms, steps, ...}; with path, also written there "
          "(.yaml; force=True replaces a file). beyond: why it would not push back as it is (a pose beyond a limit).")
      .def(
          "push_motion",
          [](board& b, const py::object& what, long long n, const py::object& backup, bool rescale, bool dry_run) {
            const auto k = motion_number(n);
            sv::push_source src = source_of(b, what);
            src.rescale = rescale;
            const std::string to = backup.is_none() ? std::string() : path_of(backup);
            if (!to.empty() && std::filesystem::path(to).extension() != ".bin")
              throw board_error(fault::usage, "backup: " + to + " does not end in .bin (push_motion puts a .bin back)");
            const auto r = unlocked([&] { return b.push_motion(src, k, to, dry_run); });
            return py::dict("motion"_a = r.motion, "address"_a = r.address, "layout"_a = r.layout,
                            "bytes"_a = r.bytes.size(), "hex"_a = fmt::format("{}", rcb4::hex_view{r.bytes}),
                            "unchanged"_a = r.unchanged, "dry_run"_a = r.dry_run,
                            "backup"_a = r.backup.empty() ? py::object(py::none()) : py::object(py::str(r.backup)),
                            "summary"_a = r.summary, "notes"_a = r.notes,
                            "name"_a = r.name.empty() ? py::object(py::none()) : py::object(py::str(r.name)));
          },
          "what"_a, "n"_a, "backup"_a = py::none(), "rescale"_a = false, "dry_run"_a = false,
          "Writes a motion file (.yaml), a backup (.bin), or steps (a list, or pull_motion's dict) into motion n: "
          "checked, the old bytes saved to backup (a new .bin; default motion-N-DATE.bin here), written, read back. "
          "Returns the report: address, bytes, backup, notes, ...")
      .def(
          "play_motion_file",
          [](board& b, const py::object& what, bool rescale, double timeout) {
            if (!py::isinstance<py::list>(what) && !py::isinstance<py::dict>(what) &&
                std::filesystem::path(path_of(what)).extension() == ".bin")
              throw board_error(fault::usage,
                                "play_motion_file: " + path_of(what) + " is a slot's bytes: push it, then play");
            const auto src = source_of(b, what);
            if (!src.document)
              throw board_error(fault::usage,
                                "play_motion_file: " + src.name + " is a slot's bytes: push it, then play");
            const auto r = unlocked([&] {
              return b.play_file(*src.document, src.name, rescale, timeout, [] {
                py::gil_scoped_acquire acquire;
                return PyErr_CheckSignals() != 0;
              });
            });
            if (r.interrupted && PyErr_Occurred()) throw py::error_already_set();  // Ctrl-C: KeyboardInterrupt
            return py::dict("poses"_a = r.poses, "calls"_a = r.calls, "seconds"_a = std::round(r.seconds * 100) / 100,
                            "interrupted"_a = r.interrupted, "notes"_a = r.notes);
          },
          "what"_a, "rescale"_a = false, "timeout"_a = 60.0,
          "Plays a motion file (.yaml) or steps (a list, or pull_motion's dict) from the host, pose by pose at the "
          "board's timing; checked first as a push is (nothing sent when refused). A ROM motion it calls may run "
          "timeout seconds (then stopped: Timeout). Ctrl-C stops it (and a ROM motion it called). Nothing is written "
          "to ROM. Returns poses, calls, seconds, notes.")
      .def(
          "record",
          [](board& b, const py::object& path, const py::object& joints, double every, const py::object& seconds,
             bool free, double threshold, bool force) {
            const auto p = motion_file_path(path, force);
            std::vector<std::string> words;
            if (!joints.is_none()) {
              if (py::isinstance<py::str>(joints)) throw board_error(fault::usage, "joints: a list of names");
              for (const auto& j : joints) {
                if (!py::isinstance<py::str>(j)) throw board_error(fault::usage, "joints: a list of names");
                words.push_back(j.cast<std::string>());
              }
            }
            const double s = seconds.is_none() ? 0.0 : number_of(seconds, "seconds");
            const auto r = unlocked([&] {
              return b.record(words, every, s, threshold, free, [] {
                py::gil_scoped_acquire acquire;
                return PyErr_CheckSignals() != 0;
              });
            });
            PyErr_Clear();  // Ctrl-C ends a recording: what was recorded is the result
            const bool partial = r.document.steps.size() > 1;  // at least one pose before end
            if (!p.empty() && partial) {
              try {
                rcb4::robot::save_motion(p, r.document,
                                         fmt::format("recorded by pyrcb4: {} samples over {:.1f} s", r.samples,
                                                     std::chrono::duration<double>(r.span).count()));
              } catch (const rcb4::robot::profile_error& e) {
                throw board_error(fault::usage, e.what());
              }
            }
            auto d = document_data(r.document);
            d["samples"] = r.samples;
            d["clamped"] = r.clamped;
            d["held"] = r.held;
            d["file"] = p.empty() || !partial ? py::object(py::none()) : py::object(py::str(p));
            if (r.lost)
              raise(r.lost, "record" + (p.empty() || !partial
                                            ? std::string(": nothing recorded")
                                            : ": the " + std::to_string(r.document.steps.size() - 1) +
                                                  " poses recorded before the board stopped answering are in " + p));
            return d;
          },
          "path"_a = py::none(), "joints"_a = py::none(), "every"_a = 0.1, "seconds"_a = py::none(), "free"_a = false,
          "threshold"_a = 2.0, "force"_a = false,
          "Teach by demonstration: samples the joints (names or groups; None: all) every `every` seconds while you "
          "move the robot by hand (free=True frees them first and holds them again at the end), for `seconds` (None: "
          "until Ctrl-C), and keeps the poses that replay the movement. Returns the motion as pull_motion does; with "
          "path also written there (.yaml). Refused while a motion runs or when a joint's servo does not answer.")
      .def(
          "erase_motion",
          [](board& b, long long n, const py::object& backup) {
            const auto k = motion_number(n);
            const std::string to = backup.is_none() ? std::string() : path_of(backup);
            const auto r = unlocked([&] { return b.erase_motion(k, to); });
            return py::dict("motion"_a = r.motion, "address"_a = r.address, "unchanged"_a = r.unchanged,
                            "backup"_a = r.backup.empty() ? py::object(py::none()) : py::object(py::str(r.backup)),
                            "callers"_a = r.callers);
          },
          "n"_a, "backup"_a = py::none(),
          "Empties motion n (0xFF), its old bytes saved to backup first; callers: the used slots that call it (a play "
          "of them is refused from now on).")
      .def(
          "buttons",
          [](board& b) {
            const auto& layout = unlocked([&]() -> const rcb4::rom_layout& { return b.rom_layout(); });
            const auto t = unlocked([&] { return b.buttons(); });
            return py::dict("ram"_a = entries_data(t.ram.entries, layout),
                            "rom"_a = entries_data(t.rom.entries, layout), "same"_a = t.same());
          },
          "The button table: ram (what the board compares now), rom (what it loads at power-on), same.")
      .def(
          "set_button",
          [](board& b, const py::object& buttons, long long n) {
            const auto word = button_word(buttons);
            const auto k = motion_number(n);
            const auto& layout = unlocked([&]() -> const rcb4::rom_layout& { return b.rom_layout(); });
            return table_data(unlocked([&] { return b.set_button(word, k); }), layout);
          },
          "buttons"_a, "n"_a, "buttons ('s1+up' or a word) play motion n, in ROM and RAM; returns the table.")
      .def(
          "clear_button",
          [](board& b, const py::object& buttons) {
            const auto word = button_word(buttons);
            const auto& layout = unlocked([&]() -> const rcb4::rom_layout& { return b.rom_layout(); });
            return table_data(unlocked([&] { return b.clear_button(word); }), layout);
          },
          "buttons"_a, "buttons play nothing any more (ROM and RAM); returns the table.")
      .def(
          "press",
          [](board& b, const py::object& buttons, bool hold) {
            const auto word = button_word(buttons);
            const auto r = unlocked([&] { return b.press(word, hold); });
            return py::dict(
                "buttons"_a = mo::buttons_text(word), "entry"_a = r.entry, "held"_a = r.held,
                "motion"_a = r.state.motion ? py::object(py::int_(*r.state.motion)) : py::object(py::none()),
                "running"_a = r.state.running);
          },
          "buttons"_a, "hold"_a = false,
          "Presses buttons as a KRR receiver would: until a motion starts, then released (hold=True: kept pressed; "
          "buttons no entry plays are only held that way, for a motion's if_buttons).")
      .def(
          "release", [](board& b) { unlocked([&] { b.release(); }); }, "Releases every button.")
      .def(
          "rom_backup",
          [](board& b, const py::object& path, bool force) {
            const auto p = path_of(path);
            if (std::filesystem::exists(p) && !force)
              throw board_error(fault::usage, "path: " + p + " exists (force=True replaces it)");
            const auto version = unlocked([&] { return b.version(); });
            const auto image = unlocked([&] { return b.rom_backup(); });
            try {
              sv::save_rom_image(p, image, version);
            } catch (const sv::refused& e) {
              throw board_error(fault::usage, e.what());
            }
            return py::dict("file"_a = p, "bytes"_a = image.size(),
                            "crc32"_a = fmt::format("{:08x}", sv::crc32(image)));
          },
          "path"_a, "force"_a = false,
          "The whole ROM (262,144 bytes) into path, its CRC-32 into path.crc32 (as rcb4 rom backup writes them).")
      .def(
          "rom_restore",
          [](board& b, const py::object& path, bool no_check, bool force) {
            const auto p = path_of(path);
            std::vector<std::uint8_t> image;
            try {
              image = sv::load_rom_image(p, no_check);
            } catch (const sv::refused& e) {
              throw board_error(fault::usage, python_words(std::string("rom_restore: ") + e.what() +
                                                           (e.hint.empty() ? "" : " (" + e.hint + ")")));
            }
            const auto version = unlocked([&] { return b.version(); });
            const auto save = [&](std::span<const std::uint8_t> now) {
              const auto before =
                  (std::filesystem::path(p).parent_path() / fmt::format("rom-before-restore-{}.bin", sv::file_stamp()))
                      .string();
              sv::save_rom_image(before, now, version);
              return before;
            };
            const auto r = unlocked([&] { return b.rom_restore(image, save, force); });
            return py::dict("pieces_written"_a = r.pieces, "unchanged"_a = r.unchanged,
                            "before"_a = r.before.empty() ? py::object(py::none()) : py::object(py::str(r.before)),
                            "buttons_loaded"_a = r.buttons_loaded, "program_stopped"_a = r.program_stopped);
          },
          "path"_a, "no_check"_a = false, "force"_a = false,
          "Writes the image in path (from rom_backup or rcb4 rom backup) where it differs, each piece read back; the "
          "ROM it replaces saved beside it first. Refused while a motion runs, for an image that is no RCB-4 program "
          "(unless force=True), or one that fails its .crc32 (no_check=True: one without a .crc32).");
}

}  // namespace pyrcb4
