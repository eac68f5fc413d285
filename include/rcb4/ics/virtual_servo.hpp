// rcb4 — sans-I/O emulators of ICS servos and of their one-wire line: bytes in, bytes out, time given.
// SPDX-License-Identifier: BSL-1.0
//
// What it models (ics.md; "model" marks choices where the sources are silent):
//  - virtual_servo: an ICS 3.6 (or 3.5) servo: its ID, baud, a 64-byte EEPROM image with factory
//    bytes of its own (from a seed), the live stretch and speed (SC 1-2 writes change them, an
//    EEPROM write reloads them: model, ics.md §7.1), a position that runs to its target at a rate
//    set by speed (model: 600°/s at 127), current while it moves, a temperature on ICSSW's scale.
//    ID 0 at 115200 answers a position with header 0x80 (ics.md §2.1). A 3.5 servo ignores SC 5.
//    An EEPROM image it could not run with (ID past 31, unknown baud code) is ignored (model).
//    It stops at its EEPROM limits (model). EEPROM byte 16 bit 1 (FREE) shows whether it is limp,
//    a status that a written image never sets (ICSSW p23, ics.md §4.3).
//  - virtual_line: the wire: every byte comes back (the echo, ics.md §1), then the replies of every
//    servo that understood the frame, one after another (all of them for an ID command). A servo
//    at another rate than the line's understands nothing. Misbehaviours for tests: silent, replies
//    with one bit flipped.
#pragma once

#include <rcb4/ics/commands.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

namespace rcb4::ics {

/** Time on the emulated line, from its start. */
using line_time = std::chrono::microseconds;

/** An emulated ICS servo. Not thread-safe: one owner feeds it. */
class virtual_servo {
 public:
  /** Degrees a second at speed 127 (model). */
  static constexpr double top_speed = 600.0;

  /** A servo answering as @p id at @p baud, factory bytes from @p seed; @p ics36 answers SC 5. */
  explicit virtual_servo(servo_id id = {}, std::uint32_t baud = 115200, std::uint32_t seed = 1, bool ics36 = true)
      : ics36_(ics36) {
    // KONDO's manager defaults for a KRS-4032-34 (ics.md §4.2), then this unit's own factory bytes.
    const std::uint8_t base[64] = {5,  10, 0, 0, 0, 0,  0, 0, 0, 0, 0, 0, 0, 0, 0, 8, 2, 12, 14, 12, 0, 13,
                                   10, 12, 0, 0, 0, 10, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,  0,  0,  0, 0,
                                   0,  0,  0, 0, 0, 0,  0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,  0,  0};
    image_ = eeprom_image::parse(base).value();
    for (auto [f, v] : {std::pair{field::stretch, 60L},
                        {field::speed, 127L},
                        {field::punch, 0L},
                        {field::dead_band, 4L},
                        {field::damping, 40L},
                        {field::safe_timer, 20L},
                        {field::temperature_limit, 75L},
                        {field::current_limit, 40L},
                        {field::response, 3L},
                        {field::user_offset, 0L},
                        {field::stretch_1, 60L},
                        {field::stretch_2, 30L},
                        {field::stretch_3, 90L}})
      (void)image_.set(f, v);
    (void)image_.set(field::baud, static_cast<long>(baud));
    std::uint32_t x = seed * 2654435761u + 1;
    for (std::size_t n = 1; n <= eeprom_image::size; ++n)
      if (factory_byte(n)) {
        x ^= x << 13, x ^= x >> 17, x ^= x << 5;
        (void)image_.set_raw(n, static_cast<std::uint8_t>(x & 0x0F));
      }
    image_.set_id(id);
    show_free();
    load_live();
  }

  /** The ID it answers to. */
  servo_id id() const noexcept { return servo_id::make(image_.get(field::id)).value(); }
  /** The rate it listens at. */
  std::uint32_t baud() const noexcept { return static_cast<std::uint32_t>(image_.get(field::baud)); }
  /** Its EEPROM image. */
  const eeprom_image& image() const noexcept { return image_; }
  /** True when it is limp. */
  bool is_free() const noexcept { return free_; }
  /** Where it stands at @p t, in counts. */
  std::uint16_t position_at(line_time t) const noexcept {
    if (free_ || t <= from_t_) return static_cast<std::uint16_t>(std::lround(from_));
    const double rate = top_speed * position::counts_per_degree * speed_ / 127.0;  // counts a second
    const double run = rate * std::chrono::duration<double>(t - from_t_).count();
    const double d = target_ - from_;
    return static_cast<std::uint16_t>(std::lround(std::abs(d) <= run ? target_ : from_ + std::copysign(run, d)));
  }
  /** The live stretch (1-127). */
  std::uint8_t stretch() const noexcept { return stretch_; }
  /** The live speed (1-127). */
  std::uint8_t speed() const noexcept { return speed_; }
  /** Turns the free servo by hand to @p counts (nothing when it holds). */
  void turn(std::uint16_t counts) noexcept {
    if (free_) from_ = counts;
  }

  /**
   * The reply to the host frame @p f at @p t, appended to @p out (nothing when the frame is not
   * for it). A baud written to the EEPROM applies to the next frame (after this reply).
   */
  void answer(std::span<const std::uint8_t> f, line_time t, std::vector<std::uint8_t>& out) {
    if (image_.get(field::slave) != 0) return;  // a slave never answers (model: nor takes anything)
    const std::uint8_t me = id().value();
    const auto put = [&out](std::initializer_list<std::uint8_t> b) { out.insert(out.end(), b); };
    if (auto c = read_id::parse(f)) {
      put({static_cast<std::uint8_t>(header::id | me)});
    } else if (auto w = write_id::parse(f)) {
      image_.set_id(w->id());
      put({static_cast<std::uint8_t>(header::id | w->id().value())});
    } else if (f.empty() || (f[0] & header::id_mask) != me) {
      return;
    } else if (auto p = set_position::parse(f)) {
      const auto now = position_at(t);
      const bool compat = me == 0 && baud() == 115200;
      put({static_cast<std::uint8_t>(compat ? 0x80 : me), position::high(now), position::low(now)});
      from_ = now, from_t_ = t;
      free_ = p->target() == position::free;
      show_free();
      // model: it stops at its EEPROM limits
      target_ = free_ ? now
                      : std::clamp<double>(p->target(), static_cast<double>(image_.get(field::min_limit)),
                                           static_cast<double>(image_.get(field::max_limit)));
    } else if (auto r = read_parameter::parse(f)) {
      put({static_cast<std::uint8_t>(0x20 | me), static_cast<std::uint8_t>(r->what()), parameter(r->what(), t)});
    } else if (auto w2 = write_parameter::parse(f)) {
      if (w2->what() == sub::stretch) stretch_ = w2->value();
      if (w2->what() == sub::speed) rebase(t), speed_ = w2->value();
      if (w2->what() == sub::current) current_limit_ = w2->value();
      if (w2->what() == sub::temperature) temperature_limit_ = w2->value();
      put({static_cast<std::uint8_t>(0x40 | me), static_cast<std::uint8_t>(w2->what()), w2->value()});
    } else if (auto rp = read_position::parse(f)) {
      if (!ics36_) return;
      const auto now = position_at(t);
      put({static_cast<std::uint8_t>(0x20 | me), 0x05, position::high(now), position::low(now)});
    } else if (auto re = read_eeprom::parse(f)) {
      put({static_cast<std::uint8_t>(0x20 | me), 0x00});
      out.insert(out.end(), image_.bytes().begin(), image_.bytes().end());
    } else if (auto we = write_eeprom::parse(f)) {
      // model: an image with an ID past 31 or an unknown baud code is not taken (and not answered)
      if (we->image().get(field::id) > static_cast<long>(servo_id::max) || we->image().get(field::baud) < 0) return;
      put({static_cast<std::uint8_t>(0x40 | me), 0x00});
      rebase(t);
      image_ = we->image();
      show_free();  // the FREE bit is a status (ics.md §4.3): never taken from a written image
      load_live();
    }
  }

 private:
  /** EEPROM byte 16 bit 1 follows the servo's state: set while it is limp (ICSSW p23, ics.md §4.3). */
  void show_free() noexcept {
    const auto& f = info(field::free);
    const auto b = image_.bytes()[f.first - 1u];
    const auto bit = static_cast<std::uint8_t>(1u << f.bit);
    (void)image_.set_raw(f.first, static_cast<std::uint8_t>(free_ ? (b | bit) : (b & ~bit)));
  }
  void load_live() noexcept {
    stretch_ = static_cast<std::uint8_t>(image_.get(field::stretch));
    speed_ = static_cast<std::uint8_t>(image_.get(field::speed));
    current_limit_ = static_cast<std::uint8_t>(image_.get(field::current_limit));
    temperature_limit_ = static_cast<std::uint8_t>(image_.get(field::temperature_limit));
  }
  void rebase(line_time t) noexcept {
    from_ = position_at(t);
    from_t_ = t;
  }
  std::uint8_t parameter(sub s, line_time t) const noexcept {
    const bool moving = !free_ && position_at(t) != static_cast<std::uint16_t>(std::lround(target_));
    switch (s) {
      case sub::stretch: return stretch_;
      case sub::speed: return speed_;
      case sub::current: return moving ? 5 : 0;          // about 0.5 A while it runs (model)
      case sub::temperature: return moving ? 118 : 120;  // about 30 °C on ICSSW's scale (model)
      default: return 0;
    }
  }
  eeprom_image image_{};
  bool ics36_ = true;
  bool free_ = true;  // a servo powers on limp until it is given a position (model)
  double from_ = position::neutral;
  double target_ = position::neutral;
  line_time from_t_{};
  std::uint8_t stretch_ = 60, speed_ = 127, current_limit_ = 40, temperature_limit_ = 75;
};

/** Ways to make the line misbehave (for tests). */
struct line_faults {
  bool silent = false;   ///< no servo answers (the echo still comes back)
  bool corrupt = false;  ///< one bit of every reply flipped
};

/** The one-wire line with its servos: the echo, then the replies (ics.md §1). */
class virtual_line {
 public:
  /** @p servos on the wire, @p faults applied. */
  explicit virtual_line(std::vector<virtual_servo> servos, line_faults faults = {})
      : servos_(std::move(servos)), faults_(faults) {}
  /**
   * Bytes @p in sent by the host at @p rate, arriving at @p t: appends to @p out the echo of every
   * byte, then for each whole frame the replies of the servos listening at @p rate.
   */
  void feed(std::span<const std::uint8_t> in, std::uint32_t rate, line_time t, std::vector<std::uint8_t>& out) {
    out.insert(out.end(), in.begin(), in.end());
    for (auto b : in) {
      if (rx_.empty() && (b & 0x80) == 0) continue;  // not a header: wait for one
      rx_.push_back(b);
      const std::size_t need = request_size_of(rx_[0], rx_.size() > 1 ? rx_[1] : -1);
      if (rx_.size() < need) continue;
      for (auto& s : servos_)
        if (s.baud() == rate && !faults_.silent) {
          const std::size_t start = out.size();
          s.answer(rx_, t, out);
          if (faults_.corrupt && out.size() > start)
            out.back() = static_cast<std::uint8_t>(out.back() ^ (out.size() - start == 1 ? 0x40u : 0x80u));
        }
      rx_.clear();
    }
  }
  /** The servos. */
  std::vector<virtual_servo>& servos() noexcept { return servos_; }

 private:
  std::vector<virtual_servo> servos_;
  line_faults faults_;
  std::vector<std::uint8_t> rx_;
};

}  // namespace rcb4::ics
