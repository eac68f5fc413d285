// rcb4 command-line tool: decode (frames, a capture, or our own --trace lines, to descriptions)
// and encode (a command to its frame). No board needed.
// SPDX-License-Identifier: BSL-1.0
#include "app.hpp"

#include <iostream>
#include <iterator>
#include <sstream>

namespace cli {
namespace {

/** One decoded frame. */
struct decoded {
  std::string kind;  ///< request, reply, invalid, partial
  std::vector<std::uint8_t> bytes;
  std::string meaning;  ///< the description, or what is wrong
};

/** Commands whose replies carry data (protocol.md §3): the others answer ACK/NACK only. */
bool has_data_reply(std::uint8_t cmd) { return cmd <= 0x0A || cmd == 0xFD; }

/** What is wrong with a frame the codec refused, with the checksum it should have had. */
std::string why(std::span<const std::uint8_t> frame, rcb4::errc e) {
  if (e == rcb4::errc::bad_checksum && frame.size() >= 2) {
    unsigned sum = 0;
    for (std::size_t i = 0; i + 1 < frame.size(); ++i) sum += frame[i];
    return fmt::format("{}: SUM is 0x{:02X}, the bytes before it add up to 0x{:02X}", rcb4::message(e), frame.back(),
                       sum & 0xFFu);
  }
  return std::string(rcb4::message(e));
}

/** Decodes frames back to back, requests and replies in any mix (a capture). */
class decoder {
 public:
  /** Bytes of unknown direction: a request is tried first, then a reply. */
  void any(std::span<const std::uint8_t> bytes) {
    std::size_t at = 0;
    while (at < bytes.size()) {
      const auto n = one(bytes.subspan(at), true, true);
      if (n == 0) break;
      at += n;
    }
  }
  /** Bytes known to be a request (`->` in a trace) or a reply (`<-`). */
  void known(std::span<const std::uint8_t> bytes, bool is_request) {
    std::size_t at = 0;
    while (at < bytes.size()) {
      const auto n = one(bytes.subspan(at), is_request, !is_request);
      if (n == 0) break;
      at += n;
    }
  }
  std::vector<decoded> frames;

 private:
  /** Decodes one frame at the start of @p rest; returns the bytes used (0: incomplete, reported). */
  std::size_t one(std::span<const std::uint8_t> rest, bool may_request, bool may_reply) {
    auto add = [&](std::string kind, std::size_t n, std::string meaning) {
      frames.push_back(
          {std::move(kind), {rest.begin(), rest.begin() + static_cast<std::ptrdiff_t>(n)}, std::move(meaning)});
      return n;
    };
    // After a request, its reply is expected (its shape resolves the 1-byte-data/NACK look-alike).
    if (may_reply && expected_) {
      const auto rep = rcb4::parse_reply(rest, *expected_);
      if (rep.status == rcb4::parse_status::complete) {
        expected_.reset();
        return add("reply", rep.consumed, fmt::format("{}", rep.value()));
      }
    }
    const auto req = may_request ? rcb4::parse_command(rest) : rcb4::parse_result<rcb4::command>{};
    if (may_request && req.status == rcb4::parse_status::complete) {
      expected_ = rcb4::expected_reply(req.value());
      return add("request", req.consumed, fmt::format("{}", req.value()));
    }
    const auto rep = may_reply ? rcb4::parse_reply_frame(rest) : rcb4::parse_result<rcb4::reply>{};
    // A well-formed frame the codec refuses as a request (SINGLE to ICS 36) is not a data reply
    // when its command never answers with data.
    const bool refused_request = may_request && req.status == rcb4::parse_status::error && rest.size() >= 2 &&
                                 req.error != rcb4::errc::bad_checksum && !has_data_reply(rest[1]);
    if (may_reply && rep.status == rcb4::parse_status::complete && !refused_request) {
      expected_.reset();
      return add("reply", rep.consumed, fmt::format("{}", rep.value()));
    }
    const auto& status = may_request ? req.status : rep.status;
    if (status == rcb4::parse_status::need_more &&
        (!may_reply || !may_request || rep.status == rcb4::parse_status::need_more)) {
      add("partial", rest.size(),
          fmt::format("incomplete frame: {} more bytes expected", may_request ? req.needed : rep.needed));
      return 0;
    }
    const std::size_t size = rest[0] >= 3 && rest[0] <= rest.size() ? rest[0] : 1;
    const auto err = may_request ? req.error : rep.error;
    expected_.reset();
    return add("invalid", size,
               fmt::format("{}{}", refused_request ? "invalid request: " : "", why(rest.first(size), err)));
  }
  std::optional<rcb4::reply_shape> expected_;
};

/** True when @p s is exactly two hex digits (a byte in a trace line). */
bool hex_byte(std::string_view s) {
  return s.size() == 2 && std::isxdigit(static_cast<unsigned char>(s[0])) &&
         std::isxdigit(static_cast<unsigned char>(s[1]));
}

/** Decodes the tool's own --trace lines ("  1.234 ms  -> 03 FE 01   PING"): the arrow gives the direction. */
bool decode_trace(const std::string& text, decoder& d) {
  std::istringstream in(text);
  std::string line;
  bool any = false;
  while (std::getline(in, line)) {
    const auto tx = line.find(" -> "), rx = line.find(" <- ");
    if (tx == std::string::npos && rx == std::string::npos) continue;
    const bool request = tx != std::string::npos && (rx == std::string::npos || tx < rx);
    std::istringstream words(line.substr((request ? tx : rx) + 4));
    std::string w;
    std::vector<std::uint8_t> bytes;
    while (words >> w && hex_byte(w)) bytes.push_back(static_cast<std::uint8_t>(std::stoi(w, nullptr, 16)));
    if (bytes.empty()) continue;
    d.known(bytes, request);
    any = true;
  }
  return any;
}

int decode(const std::vector<std::string>& words, const globals& g) {
  std::string text;
  if (words.empty() || (words.size() == 1 && words[0] == "-"))
    text.assign(std::istreambuf_iterator<char>(std::cin), std::istreambuf_iterator<char>());
  else
    text = join(words);
  decoder d;
  if (!decode_trace(text, d)) {
    const auto bytes = parse_hex(text, "decode");
    if (bytes.empty()) throw usage_error("decode: no bytes given");
    d.any(bytes);
  }
  std::size_t bad = 0;
  json frames = json::array();
  for (const auto& f : d.frames) {
    bad += f.kind == "invalid" || f.kind == "partial";
    if (g.json) {
      json j;
      j["kind"] = f.kind;
      j["hex"] = fmt::format("{}", rcb4::hex(f.bytes));
      j[f.kind == "request" || f.kind == "reply" ? "meaning" : "error"] = f.meaning;
      frames.push_back(j);
    } else {
      fmt::print("{:<8} {:<30}  {}\n", f.kind, rcb4::hex(f.bytes),
                 f.kind == "request" || f.kind == "reply" ? f.meaning : "(" + f.meaning + ")");
    }
  }
  if (g.json) {
    json j;
    j["frames"] = frames;
    j["bad"] = bad;
    emit(j);
  }
  return bad ? exit_board : exit_ok;
}

// ---- encode ------------------------------------------------------------------------------------

rcb4::servo_position parse_position(std::string_view v) {
  if (v == "free") return rcb4::servo_position::free();
  if (v == "hold") return rcb4::servo_position::hold();
  return checked<rcb4::servo_position>(parse_int(v, "POS", 0, 16383), "POS");
}

std::pair<rcb4::ics_number, std::string_view> ics_pair(std::string_view item) {
  const auto eq = item.find('=');
  if (eq == std::string_view::npos) throw usage_error(fmt::format("expected ICS=VALUE, not '{}'", item));
  return {checked<rcb4::ics_number>(parse_int(item.substr(0, eq), "ICS", 0, 35), "ICS"), item.substr(eq + 1)};
}

template <class R>
rcb4::command must(R r, std::string_view what) {
  if (!r) throw usage_error(fmt::format("{}: {}", what, rcb4::message(r.error())));
  return rcb4::command{*r};
}

int print_frame(const rcb4::command& cmd, const globals& g) {
  const auto frame = rcb4::encode(cmd);
  if (g.json) {
    json j;
    j["hex"] = fmt::format("{}", rcb4::hex(frame.bytes()));
    j["meaning"] = fmt::format("{}", cmd);
    emit(j);
  } else {
    fmt::print("{}\n  {}\n", rcb4::hex(frame.bytes()), cmd);
  }
  return exit_ok;
}

/** Declares `encode NAME`, whose @p make builds the command from the parsed options. */
template <class Make>
CLI::App* encoder(CLI::App* encode, context& ctx, std::string name, std::string about, Make make) {
  auto* cmd = encode->add_subcommand(std::move(name), std::move(about));
  on_run(cmd, ctx, [&ctx, make] { return print_frame(make(), ctx.g); });
  return cmd;
}

void add_encoders(CLI::App* encode, context& ctx) {
  encoder(encode, ctx, "ping", "ACK check 04 FE 06 08", [] { return rcb4::command{rcb4::ping{}}; });
  encoder(encode, ctx, "version", "VERSION", [] { return rcb4::command{rcb4::version{}}; });
  encoder(encode, ctx, "return", "RETURN from a CALL", [] { return rcb4::command{rcb4::ret{}}; });

  struct servo_args {
    std::string ics, pos;
    long long frames = 30;
  };
  auto sv = std::make_shared<servo_args>();
  auto* servo = encoder(encode, ctx, "servo", "SINGLE servo (0x0F)", [sv] {
    return rcb4::command{rcb4::single_servo(checked<rcb4::ics_number>(parse_int(sv->ics, "ICS", 0, 35), "ICS"),
                                            parse_position(sv->pos), checked<rcb4::frames>(sv->frames, "FRAMES"))};
  });
  servo->add_option("ICS", sv->ics, "0..35")->required();
  servo->add_option("POS", sv->pos, "0..16383, free or hold")->required();
  servo->add_option("FRAMES", sv->frames, "0..255 (default 30)")->check(int_range(0, 255));

  struct set_args {
    std::string first;
    std::vector<std::string> items;
  };
  auto cs = std::make_shared<set_args>();
  auto* cnst = encoder(encode, ctx, "const", "CONST-frame multi servo (0x10)", [cs] {
    const auto f = checked<rcb4::frames>(parse_int(cs->first, "FRAMES", 0, 255), "FRAMES");
    rcb4::servo_set<rcb4::servo_position> set;
    for (const auto& item : cs->items) {
      const auto [ics, v] = ics_pair(item);
      if (set.contains(ics)) throw usage_error(fmt::format("ICS {} is given twice", ics.value()));
      set.insert(ics, parse_position(v));
    }
    return must(rcb4::const_servo::make(set, f), "encode const");
  });
  cnst->add_option("FRAMES", cs->first, "0..255")->required();
  cnst->add_option("ICS=POS", cs->items, "POS 0..16383, free or hold")->required();

  auto ps = std::make_shared<set_args>();
  auto* params = encoder(encode, ctx, "params", "SPEED/STRETCH (0x12)", [ps] {
    rcb4::servo_set<rcb4::servo_param> set;
    for (const auto& item : ps->items) {
      const auto [ics, v] = ics_pair(item);
      if (set.contains(ics)) throw usage_error(fmt::format("ICS {} is given twice", ics.value()));
      set.insert(ics, checked<rcb4::servo_param>(parse_int(v, "VALUE", 1, 127), "VALUE"));
    }
    return must(
        rcb4::servo_params::make(ps->first == "speed" ? rcb4::param_kind::speed : rcb4::param_kind::stretch, set),
        "encode params");
  });
  params->add_option("KIND", ps->first, "speed or stretch")->required()->check(CLI::IsMember({"speed", "stretch"}));
  params->add_option("ICS=VALUE", ps->items, "VALUE 1..127")->required();

  struct memory_args {
    std::string memory, address, len;
    std::vector<std::string> bytes;
    std::vector<std::uint8_t> literal;  // kept alive until the frame is encoded
  };
  auto rd = std::make_shared<memory_args>();
  auto* read = encoder(encode, ctx, "read", "MOV from RAM or ROM to COM", [rd] {
    const bool ram = rd->memory == "ram";
    const auto addr = parse_int(rd->address, "ADDR", 0, (ram ? rcb4::ram_size : rcb4::rom_size) - 1);
    const auto n = checked<rcb4::transfer_size>(parse_int(rd->len, "LEN", 1, 128), "LEN");
    return ram ? must(rcb4::move::read_ram(checked<rcb4::ram_address>(addr, "ADDR"), n), "encode read")
               : must(rcb4::move::read_rom(checked<rcb4::rom_address>(addr, "ADDR"), n), "encode read");
  });
  read->add_option("MEMORY", rd->memory, "ram or rom")->required()->check(CLI::IsMember({"ram", "rom"}));
  read->add_option("ADDR", rd->address, "decimal or 0x hex")->required();
  read->add_option("LEN", rd->len, "1..128")->required();

  auto wr = std::make_shared<memory_args>();
  auto* write = encoder(encode, ctx, "write", "MOV literal to RAM or ROM", [wr] {
    const bool ram = wr->memory == "ram";
    const auto addr = parse_int(wr->address, "ADDR", 0, (ram ? rcb4::ram_size : rcb4::rom_size) - 1);
    wr->literal = parse_hex(join(wr->bytes), "BYTES");
    return ram ? must(rcb4::move::write_ram(checked<rcb4::ram_address>(addr, "ADDR"), wr->literal), "encode write")
               : must(rcb4::move::write_rom(checked<rcb4::rom_address>(addr, "ADDR"), wr->literal), "encode write");
  });
  write->add_option("MEMORY", wr->memory, "ram or rom")->required()->check(CLI::IsMember({"ram", "rom"}));
  write->add_option("ADDR", wr->address, "decimal or 0x hex")->required();
  write->add_option("BYTES", wr->bytes, "hex bytes")->required();

  for (const bool is_call : {true, false}) {
    auto target = std::make_shared<std::string>();
    auto* cmd = encoder(
        encode, ctx, is_call ? "call" : "jump",
        is_call ? "unconditional CALL to a ROM address" : "unconditional JUMP to a ROM address", [target, is_call] {
          const auto addr = checked<rcb4::rom_address>(parse_int(*target, "ADDR", 0, rcb4::rom_size - 1), "ADDR");
          return is_call ? rcb4::command{rcb4::call{addr}} : rcb4::command{rcb4::jump{addr}};
        });
    cmd->add_option("ADDR", *target, "ROM address, decimal or 0x hex")->required();
  }
}

}  // namespace

void add_frame_commands(CLI::App& app, context& ctx) {
  auto* decode_cmd = app.add_subcommand("decode", "frames (arguments or stdin) to descriptions");
  auto words = std::make_shared<std::vector<std::string>>();
  decode_cmd->add_option("HEX", *words, "hex bytes; none or -: read stdin (hex, or the lines of rcb4 --trace)");
  decode_cmd->footer(
      "Decodes RCB-4 frames (requests and replies back to back, e.g. a capture) into descriptions.\n"
      "A reply right after a request is parsed with that request's expected shape. The lines that\n"
      "rcb4 --trace prints decode too: their arrows say which frames are requests (->) and replies (<-).\n"
      "Exit code 1 when a frame is invalid or incomplete.\n"
      "examples:\n"
      "  rcb4 decode 07 0F 00 0A 4C 1D 89\n"
      "  echo \"0A 00 20 00 00 00 00 00 02 2C\" | rcb4 decode\n"
      "  rcb4 --trace servo list 2>&1 >/dev/null | rcb4 decode");
  on_run(decode_cmd, ctx, [&ctx, words] { return decode(*words, ctx.g); });

  auto* encode = app.add_subcommand("encode", "a command's frame (hex, and its meaning)");
  encode->require_subcommand(1);
  add_encoders(encode, ctx);
}

}  // namespace cli
