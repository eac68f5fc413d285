// rcb4 command-line tool: the subcommands that talk to a board.
// SPDX-License-Identifier: BSL-1.0
#include "cli.hpp"

#include <rcb4/transport/cpu_latency.hpp>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <map>
#include <thread>

namespace cli {
namespace {

using namespace std::chrono_literals;
using rcb4::ics_number;

constexpr std::string_view help_text =
    R"(usage: rcb4 [--device D] [--baud B] [--timeout MS] [--trace] [--json] COMMAND ...

device commands (no --device: an in-process virtual board, so all of them work without a robot):
  ping [--count N]                  round trip to the board
  version                           the board's VERSION field
  config [show]                     the config register, decoded
  config set KEY=VALUE ...          ics, program, vector-jump, interp-message, led = on|off;
                                    period = 10|15|20|25 (ms); ics-baud = 115200|625000|1250000;
                                    baud = 115200|625000|1250000 (switches the board, then follows)
  read ram|rom|ics ADDR LEN [--ics N]        read memory (any length), hex dump
  write ram|rom|ics ADDR BYTES [--ics N]     write hex bytes, e.g. "12 34" (any length)
  servo list                        allocated slots: trim, position, target, degrees
  servo get ICS ...                 the same for some servos
  servo move ICS=POS[@FRAMES] ... [--frames N] [--deg]
                                    move servos (POS raw 0..16383, or degrees with --deg);
                                    FRAMES per servo, else --frames (default 30)
  servo free|hold [ICS ...|all]     torque off / hold position (default: all allocated)
  servo speed|stretch VALUE [ICS ...|all]    ICS parameter 1..127
  sensors                           AD0..AD10, battery volts, PIO, receiver buttons and PA1..PA4
  monitor [--hz N] [--count N]      live table of servo positions and sensors until Ctrl-C
  motion play N [--wait] [--timeout S] [--layout 1.3|2.0|2.2] [--release]
  motion stop|resume|status         suspend / continue / show the ROM program's motion state
  motion wait [--timeout S]         until no motion runs, with a progress line
  bench [--count N] [--low-latency] round trips and control cycles per second vs the wire limit;
                                    --low-latency holds the CPUs' wake-up latency at 0 us meanwhile
                                    (a PM QoS request on /dev/cpu_dma_latency: root)

other commands: list, doctor, decode, encode, serve (each has --help)
)";

/** Options after the subcommand words: --name value pairs and flags; the rest are positionals. */
struct parsed {
  std::vector<std::string_view> positional;
  std::map<std::string_view, std::string_view> values;
  std::vector<std::string_view> flags;
  bool flag(std::string_view f) const { return std::find(flags.begin(), flags.end(), f) != flags.end(); }
  std::optional<std::string_view> value(std::string_view k) const {
    auto it = values.find(k);
    if (it == values.end()) return std::nullopt;
    return it->second;
  }
};

parsed parse(const std::vector<std::string_view>& in, std::initializer_list<std::string_view> with_value,
             std::initializer_list<std::string_view> flags) {
  parsed p;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const auto a = in[i];
    if (a.size() > 2 && a.substr(0, 2) == "--") {
      if (std::find(with_value.begin(), with_value.end(), a) != with_value.end()) {
        if (i + 1 >= in.size()) throw usage_error{fmt::format("{} needs a value", a)};
        p.values[a] = in[++i];
      } else if (std::find(flags.begin(), flags.end(), a) != flags.end()) {
        p.flags.push_back(a);
      } else {
        throw usage_error{fmt::format("unknown option '{}'", a)};
      }
    } else {
      p.positional.push_back(a);
    }
  }
  return p;
}

std::string_view word(const parsed& p, std::size_t i, std::string_view what) {
  if (i >= p.positional.size()) throw usage_error{fmt::format("missing {}", what)};
  return p.positional[i];
}

void no_more(const parsed& p, std::size_t n) {
  if (p.positional.size() > n) throw usage_error{fmt::format("unexpected argument '{}'", p.positional[n])};
}

std::string json_bytes(std::span<const std::uint8_t> b) {
  std::string s = "[";
  for (std::size_t i = 0; i < b.size(); ++i) s += fmt::format("{}{}", i ? "," : "", b[i]);
  return s + "]";
}

/** Seconds as a duration, for --timeout S. */
std::chrono::milliseconds seconds_option(const parsed& p, std::string_view name, double fallback) {
  double s = fallback;
  if (auto v = p.value(name)) {
    const std::string str(*v);
    char* end = nullptr;
    s = std::strtod(str.c_str(), &end);
    if (end != str.c_str() + str.size() || !(s > 0) || s > 3600)
      throw usage_error{fmt::format("{}: expected seconds (0 < S <= 3600), not '{}'", name, *v)};
  }
  return std::chrono::milliseconds(static_cast<long long>(s * 1000));
}

// ---- ping, version, config -----------------------------------------------------------------

int ping_cmd(session& s, const parsed& p, const globals& g) {
  no_more(p, 0);
  const auto n = p.value("--count") ? parse_int(*p.value("--count"), "--count", 1, 1000000) : 1;
  std::vector<double> us;
  for (long long i = 0; i < n; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    s.c().execute(rcb4::ping{rcb4::ping_form::short_});  // 03 FE 01: a loopback cannot fake its ACK
    us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
    if (!g.json && n <= 10) fmt::print("ACK from {} in {:.0f} us\n", s.where(), us.back());
  }
  const auto [lo, hi] = std::minmax_element(us.begin(), us.end());
  double sum = 0;
  for (double v : us) sum += v;
  // Late replies are retried and resynchronised by the client: say so, or "ACK" hides a bad line.
  const auto& k = s.c().counters();
  const auto retries = k.retries.load(), timeouts = k.timeouts.load(), resyncs = k.resyncs.load();
  if (g.json)
    fmt::print(
        "{{\"count\":{},\"min_us\":{:.1f},\"avg_us\":{:.1f},\"max_us\":{:.1f},\"baud\":{},\"retries\":{},"
        "\"timeouts\":{},\"resyncs\":{}}}\n",
        n, *lo, sum / static_cast<double>(n), *hi, s.baud(), retries, timeouts, resyncs);
  else if (n > 1)
    fmt::print("{} pings: min {:.0f} us, avg {:.0f} us, max {:.0f} us ({} baud)\n", n, *lo,
               sum / static_cast<double>(n), *hi, s.baud());
  if (!g.json && (retries > 0 || timeouts > 0))
    fmt::print("{} retries after {} timeouts ({} resyncs): replies come late or get lost\n", retries, timeouts,
               resyncs);
  return exit_ok;
}

int version_cmd(session& s, const parsed& p, const globals& g) {
  no_more(p, 0);
  rcb4::ops::read_version op;
  rcb4::transport::error_code ec;
  rcb4::transport::run(s.c(), op, ec);
  if (ec) throw rcb4::transport::system_error(ec, "version");
  const auto& v = op.value();
  if (g.json)
    fmt::print("{{\"version\":\"{}\",\"raw\":{}}}\n", v, json_bytes(op.raw()));
  else
    fmt::print("{}\n  raw: {}\n", v, rcb4::hex(op.raw()));
  return exit_ok;
}

const char* on_off(bool b) { return b ? "on" : "off"; }

void print_config(const rcb4::config_word& c, const globals& g) {
  using rcb4::bits_per_second;
  if (g.json) {
    fmt::print(
        "{{\"word\":{},\"ics\":{},\"program\":{},\"interp_message\":{},\"vector_jump\":{},\"period_ms\":{},"
        "\"baud\":{},\"zero\":{},\"carry\":{},\"program_error\":{},\"ics_baud\":{},\"led\":{}}}\n",
        c.encode(), c.ics_enabled, c.rom_program, c.interpolation_message, c.vector_jump, rcb4::milliseconds(c.period),
        bits_per_second(c.com_baud), c.zero_flag, c.carry_flag, c.program_error, bits_per_second(c.ics_baud), c.led);
    return;
  }
  fmt::print("config 0x{:04X}\n", c.encode());
  fmt::print("  ics             {:<8} servos driven (bit 0)\n", on_off(c.ics_enabled));
  fmt::print("  program         {:<8} ROM program runs (bit 1)\n", on_off(c.rom_program));
  fmt::print("  interp-message  {:<8} message at the end of interpolation (bit 2)\n", on_off(c.interpolation_message));
  fmt::print("  vector-jump     {:<8} (bit 3)\n", on_off(c.vector_jump));
  fmt::print("  period          {:<8} servo output period (bits 4-5)\n",
             fmt::format("{} ms", rcb4::milliseconds(c.period)));
  fmt::print("  baud            {:<8} COM rate (bits 6-7)\n", bits_per_second(c.com_baud));
  fmt::print("  zero, carry     {}, {}\n", on_off(c.zero_flag), on_off(c.carry_flag));
  fmt::print("  program-error   {}\n", on_off(c.program_error));
  fmt::print("  ics-baud        {:<8} (bits 13-14)\n", bits_per_second(c.ics_baud));
  fmt::print("  led             {}\n", on_off(c.led));
}

bool parse_on_off(std::string_view key, std::string_view v) {
  if (v == "on" || v == "1" || v == "true") return true;
  if (v == "off" || v == "0" || v == "false") return false;
  throw usage_error{fmt::format("config set {}: expected on or off, not '{}'", key, v)};
}

rcb4::baud_code parse_baud(std::string_view key, std::string_view v) {
  const auto code = rcb4::baud_code_of(static_cast<std::uint32_t>(parse_int(v, key, 0, 100000000)));
  if (!code) throw usage_error{fmt::format("{}: {} ({})", key, v, rcb4::message(code.error()))};
  return *code;
}

int config_cmd(session& s, const parsed& p, const globals& g) {
  const auto sub = p.positional.empty() ? std::string_view("show") : p.positional[0];
  if (sub == "show") {
    no_more(p, 1);
    print_config(s.run(rcb4::ops::read_config{}), g);
    return exit_ok;
  }
  if (sub != "set") throw usage_error{fmt::format("config: expected show or set, not '{}'", sub)};
  if (p.positional.size() < 2) throw usage_error{"config set: give KEY=VALUE pairs (see rcb4 config --help)"};
  std::vector<std::pair<std::string_view, std::string_view>> changes;
  std::optional<std::uint32_t> new_baud;
  for (std::size_t i = 1; i < p.positional.size(); ++i) {
    const auto kv = p.positional[i];
    const auto eq = kv.find('=');
    if (eq == std::string_view::npos) throw usage_error{fmt::format("config set: expected KEY=VALUE, not '{}'", kv)};
    const auto key = kv.substr(0, eq), value = kv.substr(eq + 1);
    static constexpr std::string_view keys[] = {"ics", "program", "vector-jump", "interp-message",
                                                "led", "period",  "ics-baud",    "baud"};
    if (std::find(std::begin(keys), std::end(keys), key) == std::end(keys))
      throw usage_error{fmt::format("config set: unknown key '{}'", key)};
    if (key == "baud")
      new_baud = rcb4::bits_per_second(parse_baud("baud", value));
    else
      changes.emplace_back(key, value);
  }
  auto apply = [&](rcb4::config_word& c) {
    for (const auto& [key, value] : changes) {
      if (key == "ics") c.ics_enabled = parse_on_off(key, value);
      if (key == "program") c.rom_program = parse_on_off(key, value);
      if (key == "vector-jump") c.vector_jump = parse_on_off(key, value);
      if (key == "interp-message") c.interpolation_message = parse_on_off(key, value);
      if (key == "led") c.led = parse_on_off(key, value);
      if (key == "ics-baud") c.ics_baud = parse_baud("ics-baud", value);
      if (key == "period") {
        const auto ms = parse_int(value, "period", 10, 25);
        if (ms % 5 != 0) throw usage_error{"period: 10, 15, 20 or 25 (ms)"};
        c.period = static_cast<rcb4::output_period>((ms - 10) / 5);
      }
    }
  };
  rcb4::config_word probe;  // validate every value before anything is sent
  apply(probe);
  if (!changes.empty()) s.run(rcb4::ops::update_config(apply));
  if (new_baud) {
    rcb4::transport::switch_baud(s.c(), *new_baud);  // the board, then this port, then a ping
    if (!g.json) fmt::print("the board now speaks {} baud (until power-off: the ROM keeps the old rate)\n", *new_baud);
  }
  print_config(s.run(rcb4::ops::read_config{}), g);
  return exit_ok;
}

// ---- memory ----------------------------------------------------------------------------------

struct memory_target {
  rcb4::ops::memory kind;
  ics_number ics{};
};

/** A usage error when @p n bytes at @p addr leave memory @p t (before anything is sent). */
void check_range(const memory_target& t, std::uint32_t addr, std::size_t n) {
  const std::uint32_t end = t.kind == rcb4::ops::memory::ram   ? rcb4::ram_size
                            : t.kind == rcb4::ops::memory::rom ? rcb4::rom_size
                                                               : 256u;
  if (addr + n > end)
    throw usage_error{fmt::format("{} bytes at 0x{:X} run outside the memory (it ends at 0x{:X})", n, addr, end)};
}

memory_target parse_memory(const parsed& p) {
  const auto m = word(p, 0, "memory: ram, rom or ics");
  memory_target t{rcb4::ops::memory::ram};
  if (m == "rom")
    t.kind = rcb4::ops::memory::rom;
  else if (m == "ics")
    t.kind = rcb4::ops::memory::ics;
  else if (m != "ram")
    throw usage_error{fmt::format("expected ram, rom or ics, not '{}'", m)};
  if (auto v = p.value("--ics")) t.ics = checked<ics_number>(parse_int(*v, "--ics", 0, 35), "--ics");
  if (t.kind == rcb4::ops::memory::ics && !p.value("--ics")) throw usage_error{"ics memory needs --ics N"};
  return t;
}

void hexdump(std::uint32_t base, std::span<const std::uint8_t> b) {
  for (std::size_t i = 0; i < b.size(); i += 16) {
    std::string ascii;
    for (std::size_t k = i; k < std::min(b.size(), i + 16); ++k)
      ascii += (b[k] >= 0x20 && b[k] < 0x7F) ? static_cast<char>(b[k]) : '.';
    fmt::print("0x{:06X}  {:<47}  {}\n", base + i, rcb4::hex(b.subspan(i, std::min<std::size_t>(16, b.size() - i))),
               ascii);
  }
}

int read_cmd(session& s, const parsed& p, const globals& g) {
  const auto t = parse_memory(p);
  const auto addr = static_cast<std::uint32_t>(parse_int(word(p, 1, "ADDR"), "ADDR", 0, rcb4::rom_size - 1));
  const auto len = static_cast<std::size_t>(parse_int(word(p, 2, "LEN"), "LEN", 1, rcb4::rom_size));
  no_more(p, 3);
  check_range(t, addr, len);
  const auto bytes = s.run(rcb4::ops::read_memory(t.kind, addr, len, t.ics));
  if (g.json)
    fmt::print("{{\"address\":{},\"bytes\":{}}}\n", addr, json_bytes(bytes));
  else
    hexdump(addr, bytes);
  return exit_ok;
}

int write_cmd(session& s, const parsed& p, const globals& g) {
  const auto t = parse_memory(p);
  const auto addr = static_cast<std::uint32_t>(parse_int(word(p, 1, "ADDR"), "ADDR", 0, rcb4::rom_size - 1));
  std::string joined;
  for (std::size_t i = 2; i < p.positional.size(); ++i) {
    joined += p.positional[i];
    joined += ' ';
  }
  const auto bytes = parse_hex(joined, "BYTES");
  if (bytes.empty()) throw usage_error{"write: give the bytes to write, e.g. \"12 34\""};
  check_range(t, addr, bytes.size());
  const auto written = s.run(rcb4::ops::write_memory(t.kind, addr, bytes, t.ics));
  const auto frames = (bytes.size() + rcb4::ops::max_write - 1) / rcb4::ops::max_write;
  if (g.json)
    fmt::print("{{\"address\":{},\"written\":{},\"frames\":{}}}\n", addr, written, frames);
  else
    fmt::print("wrote {} bytes at 0x{:06X} in {} frame{}\n", written, addr, frames, frames == 1 ? "" : "s");
  return exit_ok;
}

// ---- servos ----------------------------------------------------------------------------------

std::string position_text(std::uint16_t v) {
  const auto p = rcb4::servo_position::make(v);
  if (!p) return fmt::format("0x{:04X}", v);
  if (p->is_free()) return "FREE";
  if (p->is_hold()) return "HOLD";
  return fmt::format("{} ({:+.1f} deg)", v, rcb4::ops::to_degrees(*p));
}

void print_states(const std::vector<rcb4::ops::servo_state>& states, const globals& g) {
  if (g.json) {
    fmt::print("[");
    for (std::size_t i = 0; i < states.size(); ++i) {
      const auto& st = states[i];
      fmt::print("{}{{\"ics\":{},\"trim\":{},\"position\":{},\"target\":{}}}", i ? "," : "", st.ics.value(), st.trim,
                 st.position, st.target);
    }
    fmt::print("]\n");
    return;
  }
  fmt::print("{:>4}  {:>6}  {:<20}  {}\n", "ICS", "trim", "position", "target");
  for (const auto& st : states)
    fmt::print("{:>4}  {:>6}  {:<20}  {}\n", st.ics.value(), st.trim, position_text(st.position),
               position_text(st.target));
}

std::optional<rcb4::servo_mask> parse_servos(const parsed& p, std::size_t from) {
  if (p.positional.size() <= from || (p.positional.size() == from + 1 && p.positional[from] == "all"))
    return std::nullopt;
  rcb4::servo_mask m;
  for (std::size_t i = from; i < p.positional.size(); ++i) {
    const auto n = checked<ics_number>(parse_int(p.positional[i], "ICS", 0, 35), "ICS");
    if (m.contains(n)) throw usage_error{fmt::format("ICS {} is given twice", n.value())};
    m.insert(n);
  }
  return m;
}

/** Refuses (usage, nothing sent) servos the board has no block for: the board would ignore them. */
void require_allocated(session& s, const rcb4::servo_mask& m, std::string_view cmd) {
  const auto slots = s.run(rcb4::ops::scan_servos{});
  for (auto n : m)
    if (std::none_of(slots.begin(), slots.end(), [&](const auto& slot) { return slot.ics == n; }))
      throw usage_error{fmt::format("{}: ICS {} has no servo allocated (see rcb4 servo list)", cmd, n.value())};
}

int servo_cmd(session& s, const parsed& p, const globals& g) {
  const auto sub = word(p, 0, "servo command: list, get, move, free, hold, speed, stretch");
  if (sub == "list" || sub == "get") {
    if (sub == "list") no_more(p, 1);
    auto states = s.run(rcb4::ops::read_servo_states(rcb4::ops::link_cost::at(s.baud(), 1ms)));
    if (sub == "get") {
      const auto want = parse_servos(p, 1);
      if (!want) throw usage_error{"servo get: name the servos (ICS numbers)"};
      for (auto n : *want)
        if (std::none_of(states.begin(), states.end(), [&](const auto& st) { return st.ics == n; }))
          throw usage_error{fmt::format("servo get: ICS {} has no servo allocated (see rcb4 servo list)", n.value())};
      std::erase_if(states, [&](const auto& st) { return !want->contains(st.ics); });
    }
    print_states(states, g);
    return exit_ok;
  }
  if (sub == "move") {
    const long long default_frames = p.value("--frames") ? parse_int(*p.value("--frames"), "--frames", 0, 255) : 30;
    const bool degrees = p.flag("--deg");
    rcb4::servo_set<rcb4::timed_position> targets;
    for (std::size_t i = 1; i < p.positional.size(); ++i) {
      const auto item = p.positional[i];
      const auto eq = item.find('=');
      if (eq == std::string_view::npos) throw usage_error{fmt::format("servo move: expected ICS=POS, not '{}'", item)};
      const auto ics = checked<ics_number>(parse_int(item.substr(0, eq), "ICS", 0, 35), "ICS");
      auto rest = item.substr(eq + 1);
      long long frames = default_frames;
      if (const auto at = rest.find('@'); at != std::string_view::npos) {
        frames = parse_int(rest.substr(at + 1), "FRAMES", 0, 255);
        rest = rest.substr(0, at);
      }
      rcb4::servo_position pos{};
      if (degrees) {
        const std::string str(rest);
        char* end = nullptr;
        const double d = std::strtod(str.c_str(), &end);
        if (end != str.c_str() + str.size()) throw usage_error{fmt::format("servo move: '{}' is not degrees", rest)};
        auto r = rcb4::ops::from_degrees(d);
        if (!r) throw usage_error{fmt::format("servo move: {} degrees is outside the servo's range", rest)};
        pos = *r;
      } else {
        pos = checked<rcb4::servo_position>(parse_int(rest, "POS", 0, 16383), "POS");
      }
      if (targets.contains(ics)) throw usage_error{fmt::format("servo move: ICS {} is given twice", ics.value())};
      targets.insert(ics, {pos, checked<rcb4::frames>(frames, "FRAMES")});
    }
    if (targets.empty()) throw usage_error{"servo move: give ICS=POS pairs, e.g. 0=7500 1=8000@10"};
    require_allocated(s, targets.mask(), "servo move");
    const auto moved = s.run(rcb4::ops::move_servos(targets));
    if (!g.json) fmt::print("moving {} servo{}\n", moved.size(), moved.size() == 1 ? "" : "s");
    return exit_ok;
  }
  if (sub == "free" || sub == "hold") {
    const auto which = parse_servos(p, 1);
    if (which) require_allocated(s, *which, fmt::format("servo {}", sub));
    const auto done = s.run(
        rcb4::ops::set_servo_power(sub == "free" ? rcb4::ops::power_state::free : rcb4::ops::power_state::hold, which));
    if (!g.json)
      fmt::print("{} {} servo{}\n", sub == "free" ? "freed" : "holding", done.size(), done.size() == 1 ? "" : "s");
    return exit_ok;
  }
  if (sub == "speed" || sub == "stretch") {
    const auto v = checked<rcb4::servo_param>(parse_int(word(p, 1, "VALUE (1..127)"), "VALUE", 1, 127), "VALUE");
    const auto which = parse_servos(p, 2);
    if (which) require_allocated(s, *which, fmt::format("servo {}", sub));
    const auto done = s.run(
        rcb4::ops::set_servo_param(sub == "speed" ? rcb4::param_kind::speed : rcb4::param_kind::stretch, v, which));
    if (!g.json) fmt::print("{} = {} on {} servo{}\n", sub, v.value(), done.size(), done.size() == 1 ? "" : "s");
    return exit_ok;
  }
  throw usage_error{fmt::format("servo: unknown command '{}'", sub)};
}

// ---- sensors, monitor --------------------------------------------------------------------------

std::string button_names(std::uint16_t b) {
  static constexpr std::pair<rcb4::krr_button, std::string_view> names[] = {
      {rcb4::krr_button::up, "up"},         {rcb4::krr_button::down, "down"},     {rcb4::krr_button::right, "right"},
      {rcb4::krr_button::left, "left"},     {rcb4::krr_button::triangle, "tri"},  {rcb4::krr_button::cross, "cross"},
      {rcb4::krr_button::circle, "circle"}, {rcb4::krr_button::square, "square"}, {rcb4::krr_button::s1, "S1"},
      {rcb4::krr_button::s2, "S2"},         {rcb4::krr_button::s3, "S3"},         {rcb4::krr_button::s4, "S4"}};
  std::string out;
  for (const auto& [bit, name] : names)
    if (b & static_cast<std::uint16_t>(bit)) {
      if (!out.empty()) out += '+';
      out += name;
    }
  return out.empty() ? "none" : out;
}

int sensors_cmd(session& s, const parsed& p, const globals& g) {
  no_more(p, 0);
  const auto a = s.run(rcb4::ops::read_analog{});
  const auto pio = s.run(rcb4::ops::read_pio{});
  const auto rx = s.run(rcb4::ops::read_receiver{});
  if (g.json) {
    fmt::print("{{\"ad\":[");
    for (std::size_t k = 0; k < a.values.size(); ++k) fmt::print("{}{}", k ? "," : "", a.values[k]);
    fmt::print(
        "],\"battery_volts\":{:.2f},\"pio_direction\":{},\"pio_value\":{},\"buttons\":{},\"analog\":[{},{},{},{}]}}\n",
        a.battery_volts, pio.direction, pio.value, rx.buttons, rx.analog[0], rx.analog[1], rx.analog[2], rx.analog[3]);
    return exit_ok;
  }
  fmt::print("battery   {:.2f} V (AD0 = {})\n", a.battery_volts, a.values[0]);
  for (std::size_t k = 1; k < a.values.size(); ++k) fmt::print("AD{:<2}      {}\n", k, a.values[k]);
  fmt::print("PIO       direction 0b{:010b} (1 = output), levels 0b{:010b}\n", pio.direction, pio.value);
  fmt::print("buttons   0x{:04X} {}\n", rx.buttons, button_names(rx.buttons));
  fmt::print("PA1..PA4  {} {} {} {}\n", rx.analog[0], rx.analog[1], rx.analog[2], rx.analog[3]);
  return exit_ok;
}

std::atomic<bool> interrupted{false};
extern "C" void on_signal(int) { interrupted = true; }

int monitor_cmd(session& s, const parsed& p, const globals& g) {
  no_more(p, 0);
  const auto hz = p.value("--hz") ? parse_int(*p.value("--hz"), "--hz", 1, 1000) : 5;
  const auto count = p.value("--count") ? parse_int(*p.value("--count"), "--count", 1, 100000000) : 0;
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  const bool tty = ::isatty(STDOUT_FILENO) && !g.json;
  const auto period = std::chrono::microseconds(1000000 / hz);
  auto next = std::chrono::steady_clock::now();
  for (long long n = 0; !interrupted && (count == 0 || n < count); ++n) {
    const auto states = s.run(rcb4::ops::read_servo_states(rcb4::ops::link_cost::at(s.baud(), 1ms)));
    const auto a = s.run(rcb4::ops::read_analog{});
    const auto rx = s.run(rcb4::ops::read_receiver{});
    if (g.json) {
      fmt::print("{{\"sample\":{},\"battery_volts\":{:.2f},\"buttons\":{},\"positions\":{{", n, a.battery_volts,
                 rx.buttons);
      for (std::size_t i = 0; i < states.size(); ++i)
        fmt::print("{}\"{}\":{}", i ? "," : "", states[i].ics.value(), states[i].position);
      fmt::print("}}}}\n");
    } else {
      if (tty) fmt::print("\x1b[H\x1b[2J");
      fmt::print("rcb4 monitor  {}  {} Hz  sample {}  (Ctrl-C to stop)\n", s.where(), hz, n);
      fmt::print("battery {:.2f} V   buttons {}   PA1..4 {} {} {} {}\n", a.battery_volts, button_names(rx.buttons),
                 rx.analog[0], rx.analog[1], rx.analog[2], rx.analog[3]);
      for (std::size_t i = 0; i < states.size(); ++i)
        fmt::print("ICS {:>2} {:<20}{}", states[i].ics.value(), position_text(states[i].position),
                   i % 3 == 2 || i + 1 == states.size() ? "\n" : "  ");
    }
    std::fflush(stdout);
    next += period;
    std::this_thread::sleep_until(next);  // the sampling rate the user asked for
  }
  return exit_ok;
}

// ---- motions ---------------------------------------------------------------------------------

const rcb4::rom_layout& parse_layout(const parsed& p) {
  const auto v = p.value("--layout").value_or("2.2");
  if (v == "1.3") return rcb4::hth4_1_3;
  if (v == "2.0" || v == "2.1") return rcb4::hth4_2_0;
  if (v == "2.2") return rcb4::hth4_2_2;
  throw usage_error{fmt::format("--layout: 1.3, 2.0 or 2.2 (HTH4 version), not '{}'", v)};
}

void print_motion(const rcb4::ops::motion_state& st, const globals& g) {
  if (g.json) {
    fmt::print("{{\"running\":{},\"motion\":{},\"program_counter\":{}}}\n", st.running,
               st.motion ? fmt::format("{}", *st.motion) : "null", st.program_counter);
    return;
  }
  if (!st.running)
    fmt::print("no motion running (program counter 0x{:06X})\n", st.program_counter);
  else if (st.motion)
    fmt::print("motion {} running (program counter 0x{:06X})\n", *st.motion, st.program_counter);
  else
    fmt::print("a program is running outside the motion slots (program counter 0x{:06X})\n", st.program_counter);
}

int wait_motion(session& s, const parsed& p, const globals& g, const rcb4::rom_layout& layout) {
  const auto timeout = seconds_option(p, "--timeout", 60);
  const bool tty = ::isatty(STDERR_FILENO) && !g.json;
  const auto start = std::chrono::steady_clock::now();
  rcb4::transport::error_code ec;
  const auto st = rcb4::transport::wait_motion(
      s.c(), timeout, ec,
      [&](const rcb4::ops::motion_state& m) {
        if (!tty || !m.running) return;
        const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        fmt::print(stderr, "\r  motion {} running  {:5.1f} s  pc 0x{:06X} ",
                   m.motion ? fmt::format("{}", *m.motion) : "?", t, m.program_counter);
      },
      layout);
  if (tty) fmt::print(stderr, "\r{:60}\r", "");
  if (ec) throw rcb4::transport::system_error(ec, "motion wait");
  const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!g.json) fmt::print("done after {:.1f} s\n", t);
  print_motion(st, g);
  return exit_ok;
}

int motion_cmd(session& s, const parsed& p, const globals& g) {
  const auto sub = word(p, 0, "motion command: play, stop, resume, status, wait");
  const auto& layout = parse_layout(p);
  if (sub == "play") {
    const auto n = parse_int(word(p, 1, "motion number"), "motion number", 1, layout.motion_count);
    no_more(p, 2);
    s.run(rcb4::ops::play_motion(static_cast<unsigned>(n), layout,
                                 p.flag("--release") ? rcb4::ops::servo_power::release : rcb4::ops::servo_power::keep));
    if (!g.json) fmt::print("playing motion {} ({} layout)\n", n, layout.name);
    if (p.flag("--wait")) return wait_motion(s, p, g, layout);
    return exit_ok;
  }
  no_more(p, 1);
  if (sub == "stop") {
    s.run(rcb4::ops::stop_motion{});
    if (!g.json) fmt::print("stopped (the ROM program is suspended; rcb4 motion resume continues it)\n");
    return exit_ok;
  }
  if (sub == "resume") {
    s.run(rcb4::ops::resume_motion());
    if (!g.json) fmt::print("resumed\n");
    return exit_ok;
  }
  if (sub == "status") {
    print_motion(s.run(rcb4::ops::read_motion_state(layout)), g);
    return exit_ok;
  }
  if (sub == "wait") return wait_motion(s, p, g, layout);
  throw usage_error{fmt::format("motion: unknown command '{}'", sub)};
}

// ---- bench -----------------------------------------------------------------------------------

int bench_cmd(session& s, const parsed& p, const globals& g) {
  no_more(p, 0);
  const auto n = p.value("--count") ? parse_int(*p.value("--count"), "--count", 1, 10000000) : 500;
  std::optional<rcb4::transport::cpu_latency_guard> low;
  if (p.flag("--low-latency")) {
    low.emplace(0us);
    if (!low->active()) {
      fmt::print(stderr,
                 "rcb4 bench: --low-latency: cannot write /dev/cpu_dma_latency: {}\n"
                 "  run as root, or let a group write it (udev: KERNEL==\"cpu_dma_latency\", GROUP=\"dialout\", "
                 "MODE=\"0660\")\n",
                 low->error().message());
      return exit_io;
    }
  }
  auto wire_us = [&](std::size_t bytes) { return static_cast<double>(bytes) * 11e6 / s.baud(); };
  auto rate = [&](auto&& one) {
    const auto t0 = std::chrono::steady_clock::now();
    for (long long i = 0; i < n; ++i) one();
    return static_cast<double>(n) / std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  const auto read = rcb4::move::read_ram(rcb4::ram::config, 2).value();
  const double ping_rate = rate([&] { s.c().execute(rcb4::ping{}); });
  const double read_rate = rate([&] { s.c().execute(read); });
  // Control cycle: read every allocated servo's state (planned reads), then move them all.
  const auto cost = rcb4::ops::link_cost::at(s.baud(), 1ms);
  const auto states = s.run(rcb4::ops::read_servo_states(cost));
  rcb4::servo_set<rcb4::servo_position> hold;
  for (const auto& st : states) hold.insert(st.ics, rcb4::servo_position::hold());
  const auto move_all = rcb4::const_servo::make(hold, rcb4::frames{1});
  std::size_t cycle_bytes = 0;
  {
    rcb4::ops::read_servo_states plan(cost);
    while (auto c = plan.next()) {
      const auto r = s.c().execute(*c);
      cycle_bytes += rcb4::encode(*c).size() + rcb4::expected_reply(*c).frame_size();
      plan.on_reply(r.view());
    }
    if (move_all) cycle_bytes += rcb4::encode(*move_all).size() + 4;
  }
  const double cycle_rate = rate([&] {
    s.run(rcb4::ops::read_servo_states(cost));
    if (move_all) s.c().execute(*move_all);
  });
  const double ping_limit = 1e6 / wire_us(3 + 4), read_limit = 1e6 / wire_us(10 + 5),
               cycle_limit = 1e6 / wire_us(cycle_bytes);
  if (g.json) {
    fmt::print(
        "{{\"baud\":{},\"ping_per_s\":{:.0f},\"ping_wire_limit\":{:.0f},\"read_per_s\":{:.0f},\"read_wire_limit\":{:."
        "0f},"
        "\"cycle_hz\":{:.1f},\"cycle_wire_limit_hz\":{:.1f},\"cycle_bytes\":{}}}\n",
        s.baud(), ping_rate, ping_limit, read_rate, read_limit, cycle_rate, cycle_limit, cycle_bytes);
    return exit_ok;
  }
  fmt::print("rcb4 bench against {} at {} baud, {} runs each{}\n", s.where(), s.baud(), n,
             low ? ", CPU wake-up latency held at 0 us" : "");
  fmt::print("  {:<40} {:>9.0f}/s   wire limit {:>9.0f}/s   {:.2f}x\n", "ping", ping_rate, ping_limit,
             ping_rate / ping_limit);
  fmt::print("  {:<40} {:>9.0f}/s   wire limit {:>9.0f}/s   {:.2f}x\n", "MOV read 2 bytes", read_rate, read_limit,
             read_rate / read_limit);
  fmt::print("  {:<40} {:>9.1f} Hz  wire limit {:>9.1f} Hz  {:.2f}x\n",
             fmt::format("control cycle ({} servos, {} bytes)", states.size(), cycle_bytes), cycle_rate, cycle_limit,
             cycle_rate / cycle_limit);
  if (s.is_virtual())
    fmt::print("  (the in-process virtual board is not paced: it can beat the wire limit; use rcb4 serve --pace)\n");
  return exit_ok;
}

}  // namespace

int device_command(const args& a, const globals& g) {
  if (wants_help(a)) {
    fmt::print("{}", help_text);
    return exit_ok;
  }
  using handler = int (*)(session&, const parsed&, const globals&);
  struct entry {
    std::string_view name;
    handler run;
    std::initializer_list<std::string_view> values, flags;
  };
  static const entry table[] = {
      {"ping", ping_cmd, {"--count"}, {}},
      {"version", version_cmd, {}, {}},
      {"config", config_cmd, {}, {}},
      {"read", read_cmd, {"--ics"}, {}},
      {"write", write_cmd, {"--ics"}, {}},
      {"servo", servo_cmd, {"--frames"}, {"--deg"}},
      {"sensors", sensors_cmd, {}, {}},
      {"monitor", monitor_cmd, {"--hz", "--count"}, {}},
      {"motion", motion_cmd, {"--timeout", "--layout"}, {"--wait", "--release"}},
      {"bench", bench_cmd, {"--count"}, {"--low-latency"}},
  };
  for (const auto& e : table)
    if (e.name == a.command) {
      const auto p = parse(a.list, e.values, e.flags);  // usage errors before opening anything
      session s(g);
      return e.run(s, p, g);
    }
  throw usage_error{fmt::format("unknown command '{}'", a.command)};
}

/** The help text of the device commands (for `rcb4 --help`). */
std::string_view device_help() { return help_text; }

}  // namespace cli
