// rcb4 command-line tool: the ICS commands' line and guard (cmd_ics_line.hpp).
// SPDX-License-Identifier: BSL-1.0
#include "cmd_ics_line.hpp"

namespace cli::ics_line {

sv::ics_options options_of(const globals& g) {
  sv::ics_options o;
  o.timeout = g.timeout;
  o.interrupted = [] { return signal_catcher::caught(); };  // Ctrl-C: no retry, a scan stops
  return o;
}

/**
 * Runs @p f: Ctrl-C does not cut an exchange in two (an EEPROM write is finished and reported; a
 * wait or a scan stops at the next step, exit 130), and a line that closes is told in ICS words.
 */
int guarded(const std::function<int()>& f) {
  signal_catcher signals;
  int code = exit_ok;
  try {
    code = f();
  } catch (const boost::system::system_error& e) {
    if (signal_catcher::caught()) fmt::print(stderr, "interrupted; what was under way ended so:\n");
    if (e.code() != rcb4::transport::transport_errc::closed) throw;
    throw failure(exit_io, fmt::format("the adapter's line closed ({})", plain_message(e.what())),
                  "unplugged, or the server of the pty stopped: plug it in again; `rcb4 ics eeprom show` tells what "
                  "the servo holds");
  } catch (...) {
    if (signal_catcher::caught()) fmt::print(stderr, "interrupted; what was under way ended so:\n");
    throw;
  }
  if (signal_catcher::caught() && code == exit_ok) {
    fmt::print(stderr, "interrupted (what was under way was finished first)\n");
    return exit_interrupted;
  }
  return code;
}

}  // namespace cli::ics_line
