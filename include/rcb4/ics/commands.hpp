// rcb4 — ICS 3.5/3.6 commands as constexpr values: the host's frame, the servo's reply (ics.md §2).
// SPDX-License-Identifier: BSL-1.0
//
// Wire layouts (ics.md §2.3; every data byte 7-bit; replies clear bit 7 of the header):
//   position / free  host: [80+id][pos_hi][pos_lo]       servo: [00+id][now_hi][now_lo]   (free: pos 0)
//                    ID 0 may answer [80] (ICS 2.0 compatibility at 115200, ics.md §2.1)
//   read SC 1-4      host: [A0+id][sc]                   servo: [20+id][sc][value]
//   read position    host: [A0+id][05]                   servo: [20+id][05][pos_hi][pos_lo]   (ICS 3.6)
//   read EEPROM      host: [A0+id][00]                   servo: [20+id][00][64 image bytes]
//   write SC 1-4     host: [C0+id][sc][value]            servo: [40+id][sc][value]
//   write EEPROM     host: [C0+id][00][64 image bytes]   servo: [40+id][00]
//   read ID          host: [FF][00][00][00]              servo: [E0+id]
//   write ID         host: [E0+new][01][01][01]          servo: [E0+new]
// e.g. ID 3 to +45° (8833): 83 45 01; temperature of ID 12: AC 04 → 2C 04 4B (ics.md §2.4).
// The line is one wire: a host reads back everything it sent (the echo), then the reply;
// parse_exchange() takes both and checks the echo (ics.md §1).
#pragma once

#include <rcb4/ics/eeprom.hpp>
#include <rcb4/ics/values.hpp>
#include <rcb4/parse_result.hpp>

#include <algorithm>
#include <array>
#include <span>

namespace rcb4::ics {

/** A request's bytes: at most 66 (an EEPROM write). */
struct frame {
  std::array<std::uint8_t, 66> data{};  ///< the bytes, `size` of them used
  std::size_t size = 0;                 ///< how many
  /** The bytes in use. */
  constexpr std::span<const std::uint8_t> view() const noexcept { return {data.data(), size}; }
};

/** A reply with nothing in it but its confirmation (an EEPROM write). */
struct done {
  friend constexpr bool operator==(done, done) noexcept = default;
};

namespace detail {
constexpr frame make_frame(std::initializer_list<std::uint8_t> b) noexcept {
  frame f;
  for (auto x : b) f.data[f.size++] = x;
  return f;
}
}  // namespace detail

/** Position (0x80): move to 3500-11500, or free (position 0); the reply is where it stood. */
class set_position {
 public:
  using reply_type = std::uint16_t;               ///< the position as the command arrived (free: where it went limp)
  static constexpr std::size_t request_size = 3;  ///< host bytes
  static constexpr std::size_t reply_size = 3;    ///< servo bytes
  /** @p id to @p counts: errc::ics_value_out_of_range outside 3500-11500 (0 is free(): ask for it by name). */
  static constexpr result<set_position> make(servo_id id, long counts) noexcept {
    if (counts < position::min || counts > position::max) return errc::ics_value_out_of_range;
    return set_position(id, static_cast<std::uint16_t>(counts));
  }
  /** @p id goes limp. */
  static constexpr set_position free(servo_id id) noexcept { return set_position(id, position::free); }
  /** No default: it moves a servo (ID 0 would move), so it comes from make() or free(). */
  set_position() = delete;
  /** The servo. */
  constexpr servo_id id() const noexcept { return id_; }
  /** The position sent (0: free). */
  constexpr std::uint16_t target() const noexcept { return pos_; }
  /** The host's bytes. */
  constexpr frame request() const noexcept {
    return detail::make_frame(
        {static_cast<std::uint8_t>(header::position | id_.value()), position::high(pos_), position::low(pos_)});
  }
  /** The servo's bytes (after the echo). */
  constexpr result<reply_type> parse_reply(std::span<const std::uint8_t> r) const noexcept {
    if (r.size() != reply_size || (r[1] | r[2]) > 0x7F) return errc::ics_bad_reply;
    const bool compat = id_.value() == 0 && r[0] == 0x80;  // ID 0 at 115200 keeps bit 7 (ics.md §2.1)
    if (r[0] != id_.value() && !compat) return errc::ics_bad_reply;
    return position::join(r[1], r[2]);
  }
  /** Reads a host frame (for a servo): header 0x80-0x9F, two 7-bit bytes, 0 or 3500-11500. */
  static constexpr result<set_position> parse(std::span<const std::uint8_t> f) noexcept {
    if (f.size() != request_size || (f[0] & header::command_mask) != header::position || (f[1] | f[2]) > 0x7F)
      return errc::bad_frame_size;
    const auto id = servo_id::make(f[0] & header::id_mask).value();
    const auto p = position::join(f[1], f[2]);
    if (p == position::free) return free(id);
    return make(id, p);
  }
  friend constexpr bool operator==(const set_position&, const set_position&) noexcept = default;

 private:
  constexpr set_position(servo_id id, std::uint16_t p) noexcept : id_(id), pos_(p) {}
  servo_id id_{};
  std::uint16_t pos_ = position::neutral;
};

/** Read a one-byte parameter (0xA0, SC 1-4): stretch, speed, current, temperature. */
class read_parameter {
 public:
  using reply_type = std::uint8_t;                ///< the value, 0-127
  static constexpr std::size_t request_size = 2;  ///< host bytes
  static constexpr std::size_t reply_size = 3;    ///< servo bytes
  /** @p id's @p s: errc::ics_value_out_of_range unless SC 1-4. */
  static constexpr result<read_parameter> make(servo_id id, sub s) noexcept {
    if (s == sub::eeprom || s == sub::position) return errc::ics_value_out_of_range;
    return read_parameter(id, s);
  }
  constexpr read_parameter() noexcept = default;
  /** The servo. */
  constexpr servo_id id() const noexcept { return id_; }
  /** The parameter. */
  constexpr sub what() const noexcept { return sub_; }
  /** The host's bytes. */
  constexpr frame request() const noexcept {
    return detail::make_frame({static_cast<std::uint8_t>(header::read | id_.value()), static_cast<std::uint8_t>(sub_)});
  }
  /** The servo's bytes: header 0x20 + id, the sub-command, the value. */
  constexpr result<reply_type> parse_reply(std::span<const std::uint8_t> r) const noexcept {
    if (r.size() != reply_size || r[0] != (0x20 | id_.value()) || r[1] != static_cast<std::uint8_t>(sub_) ||
        r[2] > 0x7F)
      return errc::ics_bad_reply;
    return r[2];
  }
  /** Reads a host frame (for a servo). */
  static constexpr result<read_parameter> parse(std::span<const std::uint8_t> f) noexcept {
    if (f.size() != request_size || (f[0] & header::command_mask) != header::read) return errc::bad_frame_size;
    if (f[1] < 1 || f[1] > 4) return errc::ics_value_out_of_range;
    return read_parameter(servo_id::make(f[0] & header::id_mask).value(), static_cast<sub>(f[1]));
  }
  friend constexpr bool operator==(const read_parameter&, const read_parameter&) noexcept = default;

 private:
  constexpr read_parameter(servo_id id, sub s) noexcept : id_(id), sub_(s) {}
  servo_id id_{};
  sub sub_ = sub::stretch;
};

/** Write a one-byte parameter (0xC0, SC 1-4): stretch, speed, current limit, temperature limit. */
class write_parameter {
 public:
  using reply_type = std::uint8_t;                ///< the value the servo took
  static constexpr std::size_t request_size = 3;  ///< host bytes
  static constexpr std::size_t reply_size = 3;    ///< servo bytes
  /** @p id's @p s to @p v: errc::ics_value_out_of_range outside write_range(@p s) or for SC 0 and 5. */
  static constexpr result<write_parameter> make(servo_id id, sub s, long v) noexcept {
    const auto r = write_range(s);
    if (r.max == 0 || v < r.min || v > r.max) return errc::ics_value_out_of_range;
    return write_parameter(id, s, static_cast<std::uint8_t>(v));
  }
  /** No default: it changes a servo, so it comes from make(). */
  write_parameter() = delete;
  /** The servo. */
  constexpr servo_id id() const noexcept { return id_; }
  /** The parameter. */
  constexpr sub what() const noexcept { return sub_; }
  /** The value. */
  constexpr std::uint8_t value() const noexcept { return v_; }
  /** The host's bytes. */
  constexpr frame request() const noexcept {
    return detail::make_frame(
        {static_cast<std::uint8_t>(header::write | id_.value()), static_cast<std::uint8_t>(sub_), v_});
  }
  /** The servo's bytes: header 0x40 + id, the sub-command, the value (which must be the one sent). */
  constexpr result<reply_type> parse_reply(std::span<const std::uint8_t> r) const noexcept {
    if (r.size() != reply_size || r[0] != (0x40 | id_.value()) || r[1] != static_cast<std::uint8_t>(sub_) || r[2] != v_)
      return errc::ics_bad_reply;
    return r[2];
  }
  /** Reads a host frame (for a servo). */
  static constexpr result<write_parameter> parse(std::span<const std::uint8_t> f) noexcept {
    if (f.size() != request_size || (f[0] & header::command_mask) != header::write) return errc::bad_frame_size;
    if (f[1] < 1 || f[1] > 4) return errc::ics_value_out_of_range;
    return make(servo_id::make(f[0] & header::id_mask).value(), static_cast<sub>(f[1]), f[2]);
  }
  friend constexpr bool operator==(const write_parameter&, const write_parameter&) noexcept = default;

 private:
  constexpr write_parameter(servo_id id, sub s, std::uint8_t v) noexcept : id_(id), sub_(s), v_(v) {}
  servo_id id_{};
  sub sub_ = sub::stretch;
  std::uint8_t v_ = 1;
};

/** Read the current position (0xA0, SC 5; ICS 3.6 only: a 3.5 servo stays silent). */
class read_position {
 public:
  using reply_type = std::uint16_t;               ///< the position, 14 bits
  static constexpr std::size_t request_size = 2;  ///< host bytes
  static constexpr std::size_t reply_size = 4;    ///< servo bytes
  /** @p id's position. */
  constexpr explicit read_position(servo_id id) noexcept : id_(id) {}
  constexpr read_position() noexcept = default;
  /** The servo. */
  constexpr servo_id id() const noexcept { return id_; }
  /** The host's bytes. */
  constexpr frame request() const noexcept {
    return detail::make_frame({static_cast<std::uint8_t>(header::read | id_.value()), 0x05});
  }
  /** The servo's bytes: header 0x20 + id, 05, position high, low. */
  constexpr result<reply_type> parse_reply(std::span<const std::uint8_t> r) const noexcept {
    if (r.size() != reply_size || r[0] != (0x20 | id_.value()) || r[1] != 0x05 || (r[2] | r[3]) > 0x7F)
      return errc::ics_bad_reply;
    return position::join(r[2], r[3]);
  }
  /** Reads a host frame (for a servo). */
  static constexpr result<read_position> parse(std::span<const std::uint8_t> f) noexcept {
    if (f.size() != request_size || (f[0] & header::command_mask) != header::read || f[1] != 0x05)
      return errc::bad_frame_size;
    return read_position(servo_id::make(f[0] & header::id_mask).value());
  }
  friend constexpr bool operator==(const read_position&, const read_position&) noexcept = default;

 private:
  servo_id id_{};
};

/** Read the EEPROM image (0xA0, SC 0); the reply's image is checked (eeprom_image::parse). */
class read_eeprom {
 public:
  using reply_type = eeprom_image;                ///< the image
  static constexpr std::size_t request_size = 2;  ///< host bytes
  static constexpr std::size_t reply_size = 66;   ///< servo bytes
  /** @p id's image. */
  constexpr explicit read_eeprom(servo_id id) noexcept : id_(id) {}
  constexpr read_eeprom() noexcept = default;
  /** The servo. */
  constexpr servo_id id() const noexcept { return id_; }
  /** The host's bytes. */
  constexpr frame request() const noexcept {
    return detail::make_frame({static_cast<std::uint8_t>(header::read | id_.value()), 0x00});
  }
  /** The servo's bytes: header 0x20 + id, 00, 64 image bytes (errc::ics_bad_eeprom when the image is not valid). */
  constexpr result<reply_type> parse_reply(std::span<const std::uint8_t> r) const noexcept {
    if (r.size() != reply_size || r[0] != (0x20 | id_.value()) || r[1] != 0x00) return errc::ics_bad_reply;
    return eeprom_image::parse(r.subspan(2));
  }
  /** Reads a host frame (for a servo). */
  static constexpr result<read_eeprom> parse(std::span<const std::uint8_t> f) noexcept {
    if (f.size() != request_size || (f[0] & header::command_mask) != header::read || f[1] != 0x00)
      return errc::bad_frame_size;
    return read_eeprom(servo_id::make(f[0] & header::id_mask).value());
  }
  friend constexpr bool operator==(const read_eeprom&, const read_eeprom&) noexcept = default;

 private:
  servo_id id_{};
};

/** Write the whole EEPROM image (0xC0, SC 0). Send only an image read from this servo and edited (ics.md §5). */
class write_eeprom {
 public:
  using reply_type = done;                         ///< nothing but the confirmation
  static constexpr std::size_t request_size = 66;  ///< host bytes
  static constexpr std::size_t reply_size = 2;     ///< servo bytes
  /** @p image to @p id. */
  constexpr write_eeprom(servo_id id, const eeprom_image& image) noexcept : id_(id), image_(image) {}
  /** No default: it rewrites a servo's EEPROM, so the ID and image are the caller's. */
  write_eeprom() = delete;
  /** The servo. */
  constexpr servo_id id() const noexcept { return id_; }
  /** The image sent. */
  constexpr const eeprom_image& image() const noexcept { return image_; }
  /** The host's bytes. */
  constexpr frame request() const noexcept {
    frame f = detail::make_frame({static_cast<std::uint8_t>(header::write | id_.value()), 0x00});
    for (auto b : image_.bytes()) f.data[f.size++] = b;
    return f;
  }
  /** The servo's bytes: header 0x40 + id, 00. */
  constexpr result<reply_type> parse_reply(std::span<const std::uint8_t> r) const noexcept {
    if (r.size() != reply_size || r[0] != (0x40 | id_.value()) || r[1] != 0x00) return errc::ics_bad_reply;
    return done{};
  }
  /** Reads a host frame (for a servo); the image must be valid. */
  static constexpr result<write_eeprom> parse(std::span<const std::uint8_t> f) noexcept {
    if (f.size() != request_size || (f[0] & header::command_mask) != header::write || f[1] != 0x00)
      return errc::bad_frame_size;
    auto image = eeprom_image::parse(f.subspan(2));
    if (!image) return image.error();
    return write_eeprom(servo_id::make(f[0] & header::id_mask).value(), *image);
  }
  friend constexpr bool operator==(const write_eeprom&, const write_eeprom&) noexcept = default;

 private:
  servo_id id_{};
  eeprom_image image_{};
};

/** Read the ID of the one servo on the line (FF 00 00 00); every device on the line answers (ics.md §1). */
class read_id {
 public:
  using reply_type = servo_id;                    ///< the ID answered
  static constexpr std::size_t request_size = 4;  ///< host bytes
  static constexpr std::size_t reply_size = 1;    ///< servo bytes
  /** The host's bytes. */
  constexpr frame request() const noexcept { return detail::make_frame({0xFF, 0x00, 0x00, 0x00}); }
  /** The servo's byte: 0xE0 + id (the low five bits are the ID, ics.md §2.1). */
  constexpr result<reply_type> parse_reply(std::span<const std::uint8_t> r) const noexcept {
    if (r.size() != reply_size || (r[0] & header::command_mask) != header::id) return errc::ics_bad_reply;
    return servo_id::make(r[0] & header::id_mask).value();
  }
  /** Reads a host frame (for a servo). */
  static constexpr result<read_id> parse(std::span<const std::uint8_t> f) noexcept {
    if (f.size() != request_size || f[0] != 0xFF || f[1] != 0 || f[2] != 0 || f[3] != 0) return errc::bad_frame_size;
    return read_id{};
  }
  friend constexpr bool operator==(const read_id&, const read_id&) noexcept = default;
};

/** Give the servo on the line a new ID (E0+new 01 01 01): every device on the line takes it (ics.md §1). */
class write_id {
 public:
  using reply_type = servo_id;                    ///< the ID the servo answers with
  static constexpr std::size_t request_size = 4;  ///< host bytes
  static constexpr std::size_t reply_size = 1;    ///< servo bytes
  /** Set the ID to @p id. */
  constexpr explicit write_id(servo_id id) noexcept : id_(id) {}
  /** No default: it renumbers a servo, so the ID is the caller's. */
  write_id() = delete;
  /** The new ID. */
  constexpr servo_id id() const noexcept { return id_; }
  /** The host's bytes. */
  constexpr frame request() const noexcept {
    return detail::make_frame({static_cast<std::uint8_t>(header::id | id_.value()), 0x01, 0x01, 0x01});
  }
  /** The servo's byte: 0xE0 + the new ID. */
  constexpr result<reply_type> parse_reply(std::span<const std::uint8_t> r) const noexcept {
    if (r.size() != reply_size || r[0] != (header::id | id_.value())) return errc::ics_bad_reply;
    return id_;
  }
  /** Reads a host frame (for a servo). */
  static constexpr result<write_id> parse(std::span<const std::uint8_t> f) noexcept {
    if (f.size() != request_size || (f[0] & header::command_mask) != header::id || f[1] != 1 || f[2] != 1 || f[3] != 1)
      return errc::bad_frame_size;
    return write_id(servo_id::make(f[0] & header::id_mask).value());
  }
  friend constexpr bool operator==(const write_id&, const write_id&) noexcept = default;

 private:
  servo_id id_{};
};

/**
 * What a host reads after sending @p c: the echo of its own bytes, then the reply (ics.md §1).
 * need_more until request_size + reply_size bytes are there; errc::ics_line_echo_mismatch when
 * the echo differs (a collision); else the reply parsed. `consumed` counts echo and reply.
 */
template <class Cmd>
constexpr parse_result<typename Cmd::reply_type> parse_exchange(const Cmd& c,
                                                                std::span<const std::uint8_t> rx) noexcept {
  parse_result<typename Cmd::reply_type> out;
  const auto sent = c.request();
  const std::size_t total = sent.size + Cmd::reply_size;
  const std::size_t echoed = std::min(rx.size(), sent.size);
  if (!std::equal(rx.begin(), rx.begin() + static_cast<std::ptrdiff_t>(echoed), sent.data.begin())) {
    out.status = parse_status::error;
    out.error = errc::ics_line_echo_mismatch;
    out.consumed = echoed;
    return out;
  }
  if (rx.size() < total) {
    out.needed = total - rx.size();
    return out;
  }
  auto r = c.parse_reply(rx.subspan(sent.size, Cmd::reply_size));
  out.consumed = total;
  if (!r) {
    out.status = parse_status::error;
    out.error = r.error();
    return out;
  }
  out.complete(*r);
  return out;
}

/**
 * How many bytes the host frame starting with @p head needs in all, given its second byte
 * @p second when known (a servo reading the line uses it to find each frame's end): 0 when
 * @p head cannot start a frame (bit 7 clear), and for 0xA0/0xC0 without the second byte the
 * smallest possible size.
 */
constexpr std::size_t request_size_of(std::uint8_t head, int second = -1) noexcept {
  switch (head & header::command_mask) {
    case header::position: return set_position::request_size;
    case header::read: return 2;
    case header::write: return second == 0 ? write_eeprom::request_size : 3;
    case header::id: return 4;
    default: return 0;
  }
}

}  // namespace rcb4::ics
