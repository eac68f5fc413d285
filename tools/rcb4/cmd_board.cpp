// rcb4 command-line tool: ping, version, config.
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <rcb4/robot/services/boot.hpp>

#include <algorithm>

namespace cli {
namespace {

// ---- ping --------------------------------------------------------------------------------------

int ping(session& s, long long n, const globals& g) {
  std::vector<double> us;
  for (long long i = 0; i < n; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    s.c().execute(rcb4::ping{rcb4::ping_form::short_});  // 03 FE 01: a loopback cannot fake its ACK
    us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
    if (!g.json && n <= 10)
      fmt::print("ACK from {} in {}\n", s.where(), duration_text(std::chrono::duration<double, std::micro>(us.back())));
  }
  const auto [lo, hi] = std::minmax_element(us.begin(), us.end());
  double sum = 0;
  for (double v : us) sum += v;
  const double avg = sum / static_cast<double>(n);
  // Late replies are retried and resynchronised by the client: say so, or "ACK" hides a bad line.
  const auto& k = s.c().counters();
  const auto retries = k.retries.load(), timeouts = k.timeouts.load(), resyncs = k.resyncs.load();
  if (g.json) {
    json j;
    j["where"] = s.where();
    j["baud"] = s.rate_known() ? json(s.baud()) : json(nullptr);
    j["count"] = n;
    j["min_us"] = std::round(*lo * 10) / 10;
    j["avg_us"] = std::round(avg * 10) / 10;
    j["max_us"] = std::round(*hi * 10) / 10;
    j["retries"] = retries;
    j["timeouts"] = timeouts;
    j["resyncs"] = resyncs;
    emit(j);
    return exit_ok;
  }
  using us_t = std::chrono::duration<double, std::micro>;
  if (n > 1)
    fmt::print("{}: min {}, avg {}, max {} ({})\n", plural(static_cast<std::size_t>(n), "ping"),
               duration_text(us_t(*lo)), duration_text(us_t(avg)), duration_text(us_t(*hi)),
               s.rate_known() ? fmt::format("{} baud", s.baud()) : std::string("line rate unknown"));
  if (retries > 0 || timeouts > 0)
    fmt::print("{} {} after {} ({}): replies come late or get lost\n", retries, retries == 1 ? "retry" : "retries",
               plural(timeouts, "timeout"), plural(resyncs, "resync"));
  return exit_ok;
}

// ---- version -------------------------------------------------------------------------------------

int version(session& s, const globals& g) {
  rcb4::ops::read_version op;
  rcb4::transport::error_code ec;
  rcb4::transport::run(s.c(), op, ec);
  if (ec) throw rcb4::transport::system_error(ec);
  const auto& v = op.value();
  if (g.json) {
    json j;
    j["version"] = fmt::format("{}", v);
    j["raw"] = std::vector<int>(op.raw().begin(), op.raw().end());
    emit(j);
  } else {
    fmt::print("{}\n  raw: {}\n", v, rcb4::hex(op.raw()));
  }
  return exit_ok;
}

// ---- config ----------------------------------------------------------------------------------

const char* on_off(bool b) { return b ? "on" : "off"; }

void print_config(const rcb4::config_word& c, const globals& g) {
  using rcb4::bits_per_second;
  if (g.json) {
    json j;
    j["word"] = c.encode();
    j["ics"] = c.ics_enabled;
    j["program"] = c.rom_program;
    j["interp_message"] = c.interpolation_message;
    j["vector_jump"] = c.vector_jump;
    j["period_ms"] = rcb4::milliseconds(c.period);
    j["baud"] = bits_per_second(c.com_baud);
    j["zero"] = c.zero_flag;
    j["carry"] = c.carry_flag;
    j["program_error"] = c.program_error;
    j["ics_baud"] = bits_per_second(c.ics_baud);
    j["led"] = c.led;
    emit(j);
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
  throw usage_error(fmt::format("{}: expected on or off, not '{}'", key, v));
}

rcb4::baud_code parse_baud(std::string_view key, std::string_view v) {
  const auto code = rcb4::baud_code_of(static_cast<std::uint32_t>(parse_int(v, key, 0, 100000000)));
  if (!code) throw usage_error(fmt::format("{}: {} ({})", key, v, rcb4::message(code.error())));
  return *code;
}

/** The changes of `config set`, checked before anything is sent. */
struct config_changes {
  std::vector<std::pair<std::string, std::string>> fields;  ///< KEY=VALUE for the config word
  std::optional<std::uint32_t> baud;                        ///< baud=: switch the board and follow it

  explicit config_changes(const std::vector<std::string>& pairs) {
    static constexpr std::string_view keys[] = {"ics", "program", "vector-jump", "interp-message",
                                                "led", "period",  "ics-baud",    "baud"};
    for (const auto& kv : pairs) {
      const auto eq = kv.find('=');
      if (eq == std::string::npos) throw usage_error(fmt::format("expected KEY=VALUE, not '{}'", kv));
      const auto key = kv.substr(0, eq), value = kv.substr(eq + 1);
      if (std::find(std::begin(keys), std::end(keys), key) == std::end(keys))
        throw usage_error(fmt::format("unknown key '{}' (see rcb4 config set --help)", key));
      const auto same = [&](const auto& f) { return f.first == key; };
      if ((key == "baud" && baud) || std::any_of(fields.begin(), fields.end(), same))
        throw usage_error(fmt::format("{} is given twice", key));
      if (key == "baud")
        baud = rcb4::bits_per_second(parse_baud("baud", value));
      else
        fields.emplace_back(key, value);
    }
    rcb4::config_word probe;
    apply(probe);  // every value checked here, before the session opens
  }

  void apply(rcb4::config_word& c) const {
    for (const auto& [key, value] : fields) {
      if (key == "ics") c.ics_enabled = parse_on_off(key, value);
      if (key == "program") c.rom_program = parse_on_off(key, value);
      if (key == "vector-jump") c.vector_jump = parse_on_off(key, value);
      if (key == "interp-message") c.interpolation_message = parse_on_off(key, value);
      if (key == "led") c.led = parse_on_off(key, value);
      if (key == "ics-baud") c.ics_baud = parse_baud("ics-baud", value);
      if (key == "period") {
        const auto ms = parse_int(value, "period", 0, 1000);
        if (ms < 10 || ms > 25 || ms % 5 != 0)
          throw usage_error(fmt::format("period: {} ms is not one of 10, 15, 20 or 25", value));
        c.period = static_cast<rcb4::output_period>((ms - 10) / 5);
      }
    }
  }
};

int config_set(session& s, const config_changes& ch, bool persist, const globals& g) {
  if (!ch.fields.empty()) s.run(rcb4::ops::update_config([&](rcb4::config_word& c) { ch.apply(c); }));
  if (ch.baud) {
    if (!s.rate_known())
      throw failure(exit_usage, "config set baud=: the line's rate is unknown here (a TCP bridge)",
                    "the board would switch, but the bridge's serial side would not follow: set the bridge's rate "
                    "yourself, or change the baud on a serial port");
    rcb4::transport::switch_baud(s.c(), *ch.baud);  // the board, then this port, then a ping
    if (!g.json && !persist)
      fmt::print("the board now speaks {} baud (until power-off: the ROM keeps the old rate)\n", *ch.baud);
  }
  const auto now = s.run(rcb4::ops::read_config{});
  if (persist) {
    // The changes, made to the word power-on loads (not RAM's whole word: a program stopped now
    // must not stay stopped at every power-on).
    session_link link(s, g.json);
    auto boot = rcb4::robot::services::boot_config(link);
    ch.apply(boot);
    if (ch.baud) boot.com_baud = now.com_baud;
    rcb4::robot::services::persist_config(link, boot);
    if (!g.json)
      fmt::print("kept in ROM (0x0005DC): the board starts with config word 0x{:04X} after power-on\n", boot.encode());
  }
  print_config(now, g);
  return exit_ok;
}

}  // namespace

void add_board_commands(CLI::App& app, context& ctx) {
  auto* ping_cmd = app.add_subcommand("ping", "round trip to the board (03 FE 01)");
  auto count = std::make_shared<long long>(1);
  ping_cmd->add_option("--count", *count, "pings to send; more than one prints min/avg/max and the retries")
      ->check(int_range(1, 1000000));
  on_device(ping_cmd, ctx, [&ctx, count](session& s) { return ping(s, *count, ctx.g); });

  auto* version_cmd = app.add_subcommand("version", "the board's VERSION field");
  on_device(version_cmd, ctx, [&ctx](session& s) { return version(s, ctx.g); });

  auto* config = app.add_subcommand("config", "the config register at RAM 0x0000, decoded; or change it");
  config->require_subcommand(0, 1);
  config->callback([&ctx, config] {
    if (!config->get_subcommands().empty()) return;  // `config set` chose its own action
    ctx.action = [&ctx] {
      session s(ctx.g);
      print_config(s.run(rcb4::ops::read_config{}), ctx.g);
      return exit_ok;
    };
  });
  auto* show = config->add_subcommand("show", "the config register, decoded (the default)");
  on_device(show, ctx, [&ctx](session& s) {
    print_config(s.run(rcb4::ops::read_config{}), ctx.g);
    return exit_ok;
  });
  auto* set = config->add_subcommand(
      "set", "change fields of the config register (RAM only unless --persist: power-off restores)");
  auto persist = std::make_shared<bool>(false);
  set->add_flag("--persist", *persist,
                "also write the resulting word to ROM (0x0005DC), the config the board loads at power-on");
  auto pairs = std::make_shared<std::vector<std::string>>();
  set->add_option("KEY=VALUE", *pairs,
                  "ics, program, vector-jump, interp-message, led = on|off; period = 10|15|20|25 (ms); "
                  "ics-baud = 115200|625000|1250000; baud = 115200|625000|1250000 (switches the board, then "
                  "this port follows)")
      ->required();
  set->callback([&ctx, pairs, persist] {
    auto ch = std::make_shared<config_changes>(*pairs);  // usage errors before the device opens
    ctx.action = [&ctx, ch, persist] {
      session s(ctx.g);
      return config_set(s, *ch, *persist, ctx.g);
    };
  });
}

}  // namespace cli
