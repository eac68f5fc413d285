// pyrcb4: what the binding files share (module.cpp: the Board; bind_robot.cpp: poses, trims,
// scan, the control loop).
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include "board.hpp"

#include <pybind11/pybind11.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

namespace pyrcb4 {
namespace py = pybind11;

/** Raises KeyboardInterrupt (or what a signal handler raised) when a signal came: call with the GIL. */
inline void check_signals() {
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
}

/** @p f() with the GIL released (the board's I/O lets other Python threads run), its result back. */
template <class F>
auto unlocked(F&& f) {
  py::gil_scoped_release release;
  return f();
}

/** Sleeps @p seconds with the GIL released, looking at signals every 50 ms. */
inline void sleep_interruptible(double seconds) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                            std::chrono::duration<double>(seconds));
  for (;;) {
    const auto now = std::chrono::steady_clock::now();
    if (now >= until) return;
    {
      py::gil_scoped_release release;
      std::this_thread::sleep_for(
          std::min<std::chrono::steady_clock::duration>(until - now, std::chrono::milliseconds(50)));
    }
    check_signals();
  }
}

/** Names from *args: strings, or lists/tuples of them (free("left_arm", "head"), free(["legs"])). */
inline std::vector<std::string> names_of(const py::args& args) {
  std::vector<std::string> out;
  for (const auto& a : args) {
    if (py::isinstance<py::str>(a)) {
      out.push_back(a.cast<std::string>());
    } else if (py::isinstance<py::list>(a) || py::isinstance<py::tuple>(a)) {
      for (const auto& x : a) {
        if (!py::isinstance<py::str>(x)) throw board_error(fault::usage, "joint and group names are strings");
        out.push_back(x.cast<std::string>());
      }
    } else {
      throw board_error(fault::usage, "joint and group names are strings");
    }
  }
  return out;
}

/** @p v as a number (int, float, numpy scalar); a UsageError naming @p what otherwise. */
inline double number_of(const py::handle& v, const std::string& what) {
  if (py::isinstance<py::str>(v) || py::isinstance<py::bool_>(v) || v.is_none())
    throw board_error(fault::usage, what + " must be a number, not " + py::repr(v).cast<std::string>());
  try {
    return v.cast<double>();
  } catch (const py::cast_error&) {
    throw board_error(fault::usage, what + " must be a number, not " + py::repr(v).cast<std::string>());
  }
}

/** A path given as str or os.PathLike, as os.fspath gives it. */
inline std::string path_of(const py::object& path) {
  if (!py::isinstance<py::str>(path) && !py::hasattr(path, "__fspath__"))
    throw board_error(fault::usage,
                      "a path (str or os.PathLike) was expected, not " + py::repr(path).cast<std::string>());
  return py::str(py::module_::import("os").attr("fspath")(path)).cast<std::string>();
}

/** Adds poses, trims, scan and the control loop to Board (bind_robot.cpp). */
void bind_robot(py::module_& m, py::class_<board>& cls);
/** Adds the robot services to Board: motion slots, buttons, the ROM (bind_services.cpp). */
void bind_services(py::class_<board>& cls);
/** Adds IcsServo (one ICS servo on its own line) and ics_scan (bind_ics.cpp). */
void bind_ics(py::module_& m);

}  // namespace pyrcb4
