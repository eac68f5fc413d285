// rcb4 command-line tool: list, doctor, decode, encode (no board needed, or checks around one).
// SPDX-License-Identifier: BSL-1.0
#include "cli.hpp"

#include <rcb4/transport/cpu_latency.hpp>
#include <rcb4/transport/detect.hpp>

#include <grp.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>

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
    if (p.vid == "165c" && p.pid == "0008")
      p.kind = "KONDO Dual USB Adapter HS (RCB-4 / ICS)";
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

constexpr std::string_view list_help = R"(usage: rcb4 list [--json]

Lists USB serial ports (ttyUSB*, ttyACM*) with their USB ids, recognising KONDO's adapter
(165C:0008) and FTDI chips, and the FTDI latency timer (1 ms is best for the RCB-4).
)";

constexpr std::string_view doctor_help = R"(usage: rcb4 doctor [--device PATH]

Checks what stands between this machine and a board, each with the fix: a USB adapter present,
permission to open it, membership of the dialout group, rcb4's udev rule, the FTDI latency
timer, and a board answering at 115200, 625000 or 1250000 baud. Exit code 0 when all pass,
3 when something needs fixing.
)";

constexpr std::string_view decode_help = R"(usage: rcb4 decode [HEX ...]     (no HEX, or "-": read hex from stdin)

Decodes RCB-4 frames (requests and replies, back to back, e.g. a capture) into descriptions.
A reply right after a request is parsed with that request's expected shape.
examples:
  rcb4 decode 07 0F 00 0A 4C 1D 89
  echo "0A 00 20 00 00 00 00 02 2C" | rcb4 decode
)";

constexpr std::string_view encode_help = R"(usage: rcb4 encode COMMAND ARGS [--json]

Prints the frame for a command (hex, and its meaning). Commands:
  ping | version | return
  servo ICS POS [FRAMES]                 SINGLE servo (0x0F), FRAMES default 30
  const FRAMES ICS=POS ...               CONST-frame multi servo (0x10); POS may be free or hold
  params speed|stretch ICS=VALUE ...     SPEED/STRETCH (0x12), values 1..127
  read ram|rom ADDR LEN                  MOV to COM
  write ram|rom ADDR BYTES               MOV literal
  call ADDR | jump ADDR                  unconditional CALL / JUMP to ROM ADDR
)";

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

}  // namespace

int list(const args& a, const globals& g) {
  if (wants_help(a)) {
    fmt::print("{}", list_help);
    return exit_ok;
  }
  if (!a.list.empty()) throw usage_error{fmt::format("list: unexpected argument '{}'", a.list[0])};
  const auto ports = find_ports();
  if (g.json) {
    fmt::print("[");
    for (std::size_t i = 0; i < ports.size(); ++i) {
      const auto& p = ports[i];
      fmt::print("{}{{\"path\":\"{}\",\"vid\":\"{}\",\"pid\":\"{}\",\"kind\":\"{}\",\"latency_ms\":{}}}", i ? "," : "",
                 p.path, p.vid, p.pid, p.kind, p.latency ? fmt::format("{}", *p.latency) : "null");
    }
    fmt::print("]\n");
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

int doctor(const args& a, const globals& g) {
  if (wants_help(a)) {
    fmt::print("{}", doctor_help);
    return exit_ok;
  }
  if (!a.list.empty()) throw usage_error{fmt::format("doctor: unexpected argument '{}'", a.list[0])};
  int problems = 0;
  auto report = [&](bool ok, std::string_view what, std::string_view fix = {}) {
    fmt::print("[{}] {}\n", ok ? " ok " : "FAIL", what);
    if (!ok) {
      ++problems;
      if (!fix.empty()) fmt::print("       fix: {}\n", fix);
    }
  };
  std::vector<std::string> candidates;
  const auto ports = find_ports();
  if (!g.device.empty()) {
    if (g.device.rfind("tcp:", 0) == 0)
      fmt::print("[ -- ] {} is a TCP bridge: only the board check applies\n", g.device);
    candidates.push_back(g.device);
  } else {
    report(!ports.empty(),
           ports.empty() ? "no USB serial adapter found" : fmt::format("{} USB serial port(s) found", ports.size()),
           "plug in the KONDO adapter (165C:0008) or the FTDI cable; `dmesg | tail` should show it; "
           "without hardware use the virtual board (rcb4 ping, no --device)");
    for (const auto& p : ports) candidates.push_back(p.path);
  }
  const bool root = ::geteuid() == 0;
  report(root || in_group("dialout"), root ? "running as root (no group needed)" : "member of the dialout group",
         "sudo usermod -aG dialout $USER, then log out and in again (or install the udev rule below)");
  const auto rule = installed_udev_rule();
  report(rule.has_value(),
         rule ? fmt::format("udev rule installed: {}", rule->string()) : "rcb4 udev rule not installed",
         "sudo cp cmake/udev/60-rcb4.rules /etc/udev/rules.d/ && sudo udevadm control --reload && sudo udevadm trigger "
         "(cmake --install does this when installing to /usr)");
  // Not a failure: a note for control loops (each exchange sleeps until bytes arrive).
  const auto bound = rcb4::transport::cpu_latency_bound_us();
  if (bound >= 0)
    fmt::print(
        "[ -- ] CPU wake-up latency: {}; a control loop can hold it at 0 us for its lifetime with "
        "rcb4::transport::cpu_latency_guard (root), as `rcb4 bench --low-latency` does\n",
        bound >= 1'000'000 ? std::string("no bound (idle states as configured)")
                           : fmt::format("bounded at {} us", bound));
  for (const auto& path : candidates) {
    fmt::print("-- {}\n", path);
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
      report(false, fmt::format("no board: {}", e.what()),
             "power the board (battery or supply), check the cable and that the adapter is in RCB-4 (not ICS) mode; "
             "`rcb4 --device PATH --trace ping` shows the bytes");
    }
  }
  fmt::print("{}\n", problems == 0 ? "all checks passed" : fmt::format("{} problem(s) found", problems));
  return problems == 0 ? exit_ok : exit_io;
}

int decode(const args& a, const globals& g) {
  if (wants_help(a)) {
    fmt::print("{}", decode_help);
    return exit_ok;
  }
  std::string text;
  if (a.list.empty() || (a.list.size() == 1 && a.list[0] == "-"))
    text.assign(std::istreambuf_iterator<char>(std::cin), std::istreambuf_iterator<char>());
  else
    for (auto s : a.list) {
      text += s;
      text += ' ';
    }
  const auto bytes = parse_hex(text, "decode");
  if (bytes.empty()) throw usage_error{"decode: no bytes given"};
  frame_printer printer;
  const auto lines = printer.decode(bytes);
  bool bad = false;
  for (const auto& l : lines) {
    bad = bad || l.rfind("invalid", 0) == 0 || l.rfind("partial", 0) == 0;
    if (g.json)
      fmt::print("\"{}\"\n", l);
    else
      fmt::print("{}\n", l);
  }
  return bad ? exit_board : exit_ok;
}

namespace {
rcb4::servo_position parse_position(std::string_view v) {
  if (v == "free") return rcb4::servo_position::free();
  if (v == "hold") return rcb4::servo_position::hold();
  return checked<rcb4::servo_position>(parse_int(v, "POS", 0, 16383), "POS");
}
std::pair<rcb4::ics_number, std::string_view> ics_pair(std::string_view item) {
  const auto eq = item.find('=');
  if (eq == std::string_view::npos) throw usage_error{fmt::format("expected ICS=VALUE, not '{}'", item)};
  return {checked<rcb4::ics_number>(parse_int(item.substr(0, eq), "ICS", 0, 35), "ICS"), item.substr(eq + 1)};
}
template <class R>
rcb4::command must(R r, std::string_view what) {
  if (!r) throw usage_error{fmt::format("{}: {}", what, rcb4::message(r.error()))};
  return rcb4::command{*r};
}
}  // namespace

int encode(const args& a, const globals& g) {
  if (wants_help(a) || a.list.empty()) {
    fmt::print("{}", encode_help);
    return a.list.empty() ? exit_usage : exit_ok;
  }
  const auto& w = a.list;
  auto at = [&](std::size_t i, std::string_view what) {
    if (i >= w.size()) throw usage_error{fmt::format("encode {}: missing {}", w[0], what)};
    return w[i];
  };
  auto exact = [&](std::size_t n) {
    if (w.size() > n) throw usage_error{fmt::format("encode {}: unexpected '{}'", w[0], w[n])};
  };
  const auto name = w[0];
  std::vector<std::uint8_t> literal;  // kept alive until the frame is encoded
  rcb4::command cmd;
  if (name == "ping") {
    exact(1);
    cmd = rcb4::ping{};
  } else if (name == "version") {
    exact(1);
    cmd = rcb4::version{};
  } else if (name == "return") {
    exact(1);
    cmd = rcb4::ret{};
  } else if (name == "servo") {
    exact(4);
    const auto ics = checked<rcb4::ics_number>(parse_int(at(1, "ICS"), "ICS", 0, 35), "ICS");
    const auto pos = parse_position(at(2, "POS"));
    const auto f = w.size() > 3 ? parse_int(w[3], "FRAMES", 0, 255) : 30;
    cmd = rcb4::single_servo(ics, pos, checked<rcb4::frames>(f, "FRAMES"));
  } else if (name == "const") {
    const auto f = checked<rcb4::frames>(parse_int(at(1, "FRAMES"), "FRAMES", 0, 255), "FRAMES");
    rcb4::servo_set<rcb4::servo_position> set;
    for (std::size_t i = 2; i < w.size(); ++i) {
      const auto [ics, v] = ics_pair(w[i]);
      set.insert(ics, parse_position(v));
    }
    cmd = must(rcb4::const_servo::make(set, f), "encode const");
  } else if (name == "params") {
    const auto kind = at(1, "speed or stretch");
    if (kind != "speed" && kind != "stretch") throw usage_error{"encode params: speed or stretch"};
    rcb4::servo_set<rcb4::servo_param> set;
    for (std::size_t i = 2; i < w.size(); ++i) {
      const auto [ics, v] = ics_pair(w[i]);
      set.insert(ics, checked<rcb4::servo_param>(parse_int(v, "VALUE", 1, 127), "VALUE"));
    }
    cmd = must(rcb4::servo_params::make(kind == "speed" ? rcb4::param_kind::speed : rcb4::param_kind::stretch, set),
               "encode params");
  } else if (name == "read" || name == "write") {
    const auto mem = at(1, "ram or rom");
    if (mem != "ram" && mem != "rom") throw usage_error{fmt::format("encode {}: ram or rom, not '{}'", name, mem)};
    const auto addr = parse_int(at(2, "ADDR"), "ADDR", 0, rcb4::rom_size - 1);
    if (name == "read") {
      exact(4);
      const auto n = checked<rcb4::transfer_size>(parse_int(at(3, "LEN"), "LEN", 1, 128), "LEN");
      cmd = mem == "ram" ? must(rcb4::move::read_ram(checked<rcb4::ram_address>(addr, "ADDR"), n), "encode read")
                         : must(rcb4::move::read_rom(checked<rcb4::rom_address>(addr, "ADDR"), n), "encode read");
    } else {
      std::string joined;
      for (std::size_t i = 3; i < w.size(); ++i) {
        joined += w[i];
        joined += ' ';
      }
      literal = parse_hex(joined, "BYTES");
      cmd = mem == "ram"
                ? must(rcb4::move::write_ram(checked<rcb4::ram_address>(addr, "ADDR"), literal), "encode write")
                : must(rcb4::move::write_rom(checked<rcb4::rom_address>(addr, "ADDR"), literal), "encode write");
    }
  } else if (name == "call" || name == "jump") {
    exact(2);
    const auto addr = checked<rcb4::rom_address>(parse_int(at(1, "ADDR"), "ADDR", 0, rcb4::rom_size - 1), "ADDR");
    if (name == "call")
      cmd = rcb4::call{addr};
    else
      cmd = rcb4::jump{addr};
  } else {
    throw usage_error{fmt::format("encode: unknown command '{}' (see rcb4 encode --help)", name)};
  }
  const auto frame = rcb4::encode(cmd);
  if (g.json) {
    fmt::print("{{\"hex\":\"{}\",\"meaning\":\"{}\"}}\n", rcb4::hex(frame.bytes()), cmd);
  } else {
    fmt::print("{}\n", rcb4::hex(frame.bytes()));
    fmt::print("  {}\n", cmd);
  }
  return exit_ok;
}

}  // namespace cli
