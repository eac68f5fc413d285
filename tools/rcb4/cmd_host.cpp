// rcb4 command-line tool: list (serial ports) and doctor (what stands between this machine and a board).
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <rcb4/transport/adapters.hpp>

#include <rcb4/transport/cpu_latency.hpp>
#include <rcb4/transport/detect.hpp>

#include <grp.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace cli {
namespace fs = std::filesystem;

namespace {

/** A serial port the kernel knows, with what sysfs says about it. */
struct port_info {
  std::string path;                 ///< /dev/ttyUSB0
  std::string vid, pid;             ///< USB ids (lower-case hex), empty when not USB
  std::string product;              ///< USB product string
  std::optional<unsigned> latency;  ///< FTDI latency timer (ms)
  std::string kind;                 ///< what we recognise it as
};

std::string read_line(const fs::path& p) {
  std::ifstream f(p);
  std::string s;
  std::getline(f, s);
  return s;
}

/** Where sysfs is: /sys, or $RCB4_SYSFS_ROOT (the tests point it at a fake tree). */
fs::path sysfs() {
  const char* root = std::getenv("RCB4_SYSFS_ROOT");
  return root && *root ? fs::path(root) : fs::path("/sys");
}

std::vector<port_info> find_ports() {
  std::vector<port_info> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(sysfs() / "class/tty", ec)) {
    const auto name = e.path().filename().string();
    if (name.rfind("ttyUSB", 0) != 0 && name.rfind("ttyACM", 0) != 0) continue;
    port_info p;
    p.path = "/dev/" + name;
    auto dev = fs::canonical(e.path() / "device", ec);
    for (int up = 0; !ec && up < 6 && !dev.empty(); ++up, dev = dev.parent_path())
      if (fs::exists(dev / "idVendor")) {
        p.vid = read_line(dev / "idVendor");
        p.pid = read_line(dev / "idProduct");
        p.product = read_line(dev / "product");
        break;
      }
    std::ifstream t(sysfs() / "bus/usb-serial/devices" / name / "latency_timer");
    unsigned ms = 0;
    if (t >> ms) p.latency = ms;
    const auto id = [](const std::string& hex) {
      return static_cast<std::uint16_t>(hex.empty() ? 0 : std::strtoul(hex.c_str(), nullptr, 16));
    };
    if (const auto a = rcb4::transport::find_kondo_adapter(id(p.vid), id(p.pid)))
      p.kind = fmt::format("KONDO {} ({})", a->name, rcb4::transport::line_text(a->line));
    else if (p.vid == "165c")
      p.kind = "KONDO USB device";
    else if (p.vid == "0403")
      p.kind = "FTDI USB serial";
    else
      p.kind = "USB serial";
    out.push_back(p);
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.path < b.path; });
  return out;
}

bool in_group(const char* name) {
  const group* gr = ::getgrnam(name);
  if (!gr) return false;
  std::vector<gid_t> groups(static_cast<std::size_t>(std::max(0, ::getgroups(0, nullptr))));
  const int n = ::getgroups(static_cast<int>(groups.size()), groups.data());
  for (int i = 0; i < n; ++i)
    if (groups[static_cast<std::size_t>(i)] == gr->gr_gid) return true;
  return ::getegid() == gr->gr_gid;
}

std::optional<fs::path> installed_udev_rule() {
  for (const char* dir :
       {"/etc/udev/rules.d", "/usr/lib/udev/rules.d", "/lib/udev/rules.d", "/usr/local/lib/udev/rules.d"}) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec))
      if (e.path().filename().string().find("rcb4") != std::string::npos) return e.path();
  }
  return std::nullopt;
}

int list(const globals& g) {
  const auto ports = find_ports();
  if (g.json) {
    json all = json::array();
    for (const auto& p : ports) {
      json j;
      j["path"] = p.path;
      j["vid"] = p.vid;
      j["pid"] = p.pid;
      j["product"] = p.product;
      j["kind"] = p.kind;
      j["latency_ms"] = p.latency ? json(*p.latency) : json(nullptr);
      all.push_back(j);
    }
    emit(all);
    return exit_ok;
  }
  if (ports.empty()) {
    fmt::print(
        "no USB serial ports found (plug in the KONDO adapter; `dmesg | tail` shows whether the kernel saw it)\n");
    fmt::print("without hardware, every rcb4 command works on the in-process virtual board (no --device)\n");
    return exit_ok;
  }
  for (const auto& p : ports)
    fmt::print("{:<14} {}:{}  {:<40} {}{}\n", p.path, p.vid, p.pid, p.kind, p.product,
               p.latency ? fmt::format("  latency timer {} ms", *p.latency) : "");
  return exit_ok;
}

int doctor(const globals& g) {
  std::size_t problems = 0;
  json checks = json::array();
  std::string device;  // the device the checks are about now ("" for the machine)
  auto report = [&](bool ok, std::string_view what, std::string_view fix = {}) {
    json j;
    j["ok"] = ok;
    j["check"] = what;
    if (!device.empty()) j["device"] = device;
    if (!ok && !fix.empty()) j["fix"] = fix;
    checks.push_back(j);
    if (!ok) ++problems;
    if (g.json) return;
    fmt::print("[{}] {}\n", ok ? " ok " : "FAIL", what);
    if (!ok && !fix.empty()) fmt::print("       fix: {}\n", fix);
  };
  json notes = json::array();
  auto note = [&](const std::string& text) {
    notes.push_back(text);
    if (!g.json) fmt::print("[ -- ] {}\n", text);
  };
  std::vector<std::string> candidates;
  const auto ports = find_ports();
  if (!g.device.empty()) {
    if (g.device.rfind("tcp:", 0) == 0) note(fmt::format("{} is a TCP bridge: only the board check applies", g.device));
    candidates.push_back(g.device);
  } else {
    report(!ports.empty(),
           ports.empty() ? "no USB serial adapter found" : fmt::format("{} USB serial port(s) found", ports.size()),
           "plug in the KONDO adapter (165C:0002, 0005, 0007 or 0008 for the RCB-4) or the FTDI cable; `dmesg | tail` "
           "should show it; "
           "without hardware use the virtual board (rcb4 ping, no --device)");
    for (const auto& p : ports) candidates.push_back(p.path);
  }
  const bool root = ::geteuid() == 0;
  report(root || in_group("dialout"), root ? "running as root (no group needed)" : "member of the dialout group",
         "sudo usermod -aG dialout $USER, then log out and in again (or install the udev rule below)");
  const auto rule = installed_udev_rule();
  // The rule is one way to get access (dialout is the other): missing, it fails only when
  // nothing else gives access.
  const std::string rule_fix =
      "install the rule from rcb4's sources (cmake/udev/60-rcb4.rules) into /etc/udev/rules.d/, then "
      "sudo udevadm control --reload && sudo udevadm trigger (cmake --install does this when installing to /usr)";
  if (rule)
    report(true, fmt::format("udev rule installed: {}", rule->string()));
  else if (root || in_group("dialout"))
    note("rcb4 udev rule not installed (optional here: access comes from " +
         std::string(root ? "root" : "the dialout group") +
         "; the rule also sets the FTDI latency timer to 1 ms): " + rule_fix);
  else
    report(false, "rcb4 udev rule not installed", rule_fix);
  // Not a failure: a note for control loops (each exchange sleeps until bytes arrive).
  const auto bound = rcb4::transport::cpu_latency_bound_us();
  if (bound >= 0)
    note(
        fmt::format("CPU wake-up latency: {}; a control loop can hold it at 0 us for its lifetime with "
                    "rcb4::transport::cpu_latency_guard (root), as `rcb4 bench --low-latency` does",
                    bound >= 1'000'000 ? std::string("no bound (idle states as configured)")
                                       : fmt::format("bounded at {} us", bound)));
  for (const auto& path : candidates) {
    device = path;
    if (!g.json) fmt::print("-- {}\n", path);
    if (path.rfind("tcp:", 0) != 0) {
      const bool exists = fs::exists(path);
      report(exists, fmt::format("{} exists", path), "check the path; `rcb4 list` shows the ports");
      if (!exists) continue;
      const bool rw = ::access(path.c_str(), R_OK | W_OK) == 0;
      report(rw, "read/write permission", "join dialout (above) or install the udev rule (above)");
      if (!rw) continue;
      for (const auto& p : ports)
        if (p.path == path && p.latency)
          report(*p.latency <= 1, fmt::format("FTDI latency timer {} ms", *p.latency),
                 fmt::format("echo 1 | sudo tee /sys/bus/usb-serial/devices/{}/latency_timer (the udev rule sets it)",
                             fs::path(path).filename().string()));
    }
    try {
      globals probe = g;
      probe.device = path;
      probe.baud.reset();
      session s(probe);
      const auto v = s.run(rcb4::ops::read_version{});
      report(true, fmt::format("board answers at {} baud: {}", s.baud(), v));
    } catch (const std::runtime_error& e) {  // std:: or boost::system::system_error
      report(false, fmt::format("no board: {}", plain_message(e.what())),
             "power the board (battery or supply), check the cable and that the adapter is in RCB-4 (not ICS) mode; "
             "`rcb4 --device PATH --trace ping` shows the bytes");
    }
  }
  if (g.json) {
    json j;
    j["checks"] = checks;
    j["notes"] = notes;
    j["problems"] = problems;
    j["exit"] = problems == 0 ? exit_ok : exit_io;
    emit(j);
  } else {
    fmt::print("{}\n", problems == 0 ? "all checks passed" : fmt::format("{} found", plural(problems, "problem")));
  }
  return problems == 0 ? exit_ok : exit_io;
}

}  // namespace

void add_host_commands(CLI::App& app, context& ctx) {
  auto* list_cmd = app.add_subcommand("list", "serial ports, recognising KONDO's adapter and FTDI");
  list_cmd->footer(
      "Lists USB serial ports (ttyUSB*, ttyACM*) with their USB ids, recognising KONDO's adapter\n"
      "(165C:0001, 0002, 0005-0008: which carries the RCB-4 COM line and which ICS) and FTDI chips,\n"
      "and the FTDI latency timer (1 ms is best for the RCB-4).");
  on_run(list_cmd, ctx, [&ctx] { return list(ctx.g); });

  auto* doctor_cmd = app.add_subcommand("doctor", "check permissions, dialout, udev rule, latency timer, baud");
  doctor_cmd->footer(
      "Checks what stands between this machine and a board, each with the fix: a USB adapter present,\n"
      "permission to open it, membership of the dialout group, rcb4's udev rule, the FTDI latency\n"
      "timer, and a board answering at 115200, 625000 or 1250000 baud. With --device (a global\n"
      "option: rcb4 --device D doctor) only that device is checked. Exit code 0 when all pass, 3 when\n"
      "something needs fixing.");
  on_run(doctor_cmd, ctx, [&ctx] { return doctor(ctx.g); });
}

}  // namespace cli
