// rcb4 — robot services: setting up an ICS servo on its own line (ics.md §5): find it, give it an
// ID, read, edit, back up and restore its EEPROM, move it, read its stretch, speed, current,
// temperature. One servo on a KONDO adapter in ICS mode (or `rcb4 ics serve`'s virtual one).
// SPDX-License-Identifier: BSL-1.0
//
//   my_port_link line(port);                           // an ics_link: the adapter, or virtual_link
//   ics_servo s(line, {}, {});                         // finds the baud and the lone servo's ID
//   auto e = s.read_eeprom();                          // checked: nibbles, check mark, its own ID
//   auto r = s.set_fields({{"stretch", 40}}, save);    // read, modify, back up, write, read back
//
// The rules of a careful tool (ics.md §5): every change starts from the servo's own image, read and
// checked; the old image is saved before the first write; only the fields asked change (check mark,
// factory bytes, ID and the baud byte's high nibble go back as read); the image is read back and
// compared after a write; an ID is written only when exactly one device answered the ID read;
// a backup is restored only onto the servo it came from unless forced, and never with its factory
// bytes. A refusal (`refused`) means nothing was written unless it says so.
#pragma once

#include <rcb4/ics/commands.hpp>
#include <rcb4/ics/virtual_servo.hpp>
#include <rcb4/robot/services/link.hpp>

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace rcb4::robot::services {

/** The ICS line as a front end reaches it: a serial adapter in ICS mode, a pseudo-terminal, or virtual_link. */
class ics_link {
 public:
  virtual ~ics_link() = default;
  /**
   * Sends @p request and returns what comes back (the echo, then the reply) once @p expect bytes
   * are there or @p wait has passed since the request went out: fewer bytes mean a timeout.
   * Throws when the line fails (unplugged, closed): std::system_error, or boost::system's
   * system_error from rcb4::transport::ics_port.
   */
  virtual std::vector<std::uint8_t> transact(std::span<const std::uint8_t> request, std::size_t expect,
                                             std::chrono::milliseconds wait) = 0;
  /** The bytes that arrive within @p wait (a late reply, a second device); then the line is quiet. */
  virtual std::vector<std::uint8_t> linger(std::chrono::milliseconds wait) = 0;
  /**
   * True when the last transact() or linger() stopped at a byte that failed its parity or framing
   * check (the bytes returned are those before it): never data (serial.hpp marks such bytes).
   */
  virtual bool last_damaged() const { return false; }
  /** Talks at @p baud from now on. */
  virtual void set_baud(std::uint32_t baud) = 0;
  /** The rate in use. */
  virtual std::uint32_t baud() const = 0;
};

/** How patient the service is. */
struct ics_options {
  std::chrono::milliseconds timeout{100};         ///< wait for a reply (beyond its wire time)
  std::chrono::milliseconds write_timeout{3000};  ///< wait for the reply to an EEPROM or ID write
  int tries = 3;                                  ///< tries of an exchange that timed out or came back garbled
  std::function<bool()> interrupted;              ///< a scan stops between IDs once this says true (Ctrl-C)
};

/** One servo that answered a scan. */
struct ics_found {
  std::uint32_t baud = 0;    ///< the rate it answered at
  ics::servo_id id{};        ///< its ID
  bool ics36 = false;        ///< it answers the ICS 3.6 position read (SC 5); false: ICS 3.5 (or older)
  std::uint8_t stretch = 0;  ///< its stretch, as read
  std::uint8_t speed = 0;    ///< its speed, as read
  std::string problem;       ///< not empty: something answered at this ID, but wrongly (garbled, corrupt)
};

/**
 * Every servo on the line: at each of @p bauds (empty: all three) where anything answers the ID
 * read, each ID asked its stretch and speed (which changes nothing) and the ICS 3.6 position read;
 * @p on_baud is told each rate as it starts; @p only: that ID alone. The line is left at its first rate.
 */
std::vector<ics_found> ics_scan(ics_link& l, std::span<const std::uint32_t> bauds, const ics_options& o,
                                const std::function<void(std::uint32_t)>& on_baud = {},
                                std::optional<ics::servo_id> only = {});

/** What an EEPROM change did. */
struct ics_eeprom_report {
  ics::eeprom_image before;                          ///< the image as read first
  ics::eeprom_image after;                           ///< the image read back after the write
  std::vector<std::pair<ics::field, long>> changed;  ///< the fields whose value changed (new values)
  std::string backup;                                ///< where `before` was saved
  bool written = false;                              ///< false: nothing differed (or a dry run), nothing was written
  bool verified = false;                             ///< written and read back equal (a slave cannot be read back)
  std::vector<std::string> notes;                    ///< what the user should know (a baud change, a kept ID)
};

/** Saves the servo's image before a write and returns where (a file name); throws to stop the write. */
using ics_backup = std::function<std::string(const ics::eeprom_image&)>;

/**
 * The backup both front ends use: @p dir/ics-idN-STAMP.bin (a second one within the same second
 * gets -2, -3 …: a backup never replaces a file), written with save_ics_image.
 */
ics_backup ics_backup_in(const std::string& dir, ics::servo_id id);

/**
 * Writes the raw 64 bytes of @p image to @p path (a backup: the servo's own image, byte for byte);
 * refused (usage) when it cannot, or when @p path exists and not @p replace.
 */
void save_ics_image(const std::string& path, const ics::eeprom_image& image, bool replace = false);
/** Reads a backup written by save_ics_image (64 bytes, every byte ≤ 0x0F, the check mark); a bad one is refused
 * (usage). */
ics::eeprom_image load_ics_image(const std::string& path);

/** A field and value from "name=value" (value in command units; flags on/off/true/false/1/0); refused (usage) when
 * wrong. */
std::pair<ics::field, long> parse_ics_setting(std::string_view text);

/** The servo the line reaches: found (or named), checked, and worked on. */
class ics_servo {
 public:
  /**
   * Finds the servo: at @p baud (or each rate in turn, 115200 first) and as @p id (or the ID that
   * the one device on the line gives). Refused when nothing answers (timeout), more than one device
   * answers the ID read (board), or @p id does not answer at the rate given. @p for_id_work: the ID
   * command follows (its refusal's hint says to leave one servo alone rather than to name one).
   */
  ics_servo(ics_link& l, std::optional<ics::servo_id> id, std::optional<std::uint32_t> baud, ics_options o = {},
            bool for_id_work = false);

  /** Its ID. */
  ics::servo_id id() const noexcept { return id_; }
  /** The rate it answers at. */
  std::uint32_t baud() const noexcept { return l_.baud(); }

  /**
   * The ID the one device on the line answers with; refused (board) when more than one answers
   * (@p for_id_write: the hint says to leave one servo alone, else to name it with --id).
   */
  ics::servo_id read_id(bool for_id_write = true);
  /**
   * Gives the servo alone on the line the ID @p id: checked first (one device, the one found),
   * then read back; nothing is written when it has that ID already.
   */
  ics::servo_id set_id(ics::servo_id id);

  /**
   * The EEPROM image, checked (nibbles, check mark, its ID field the servo's own) and verified: read
   * until two reads agree (at most four reads), since an image has no checksum and a byte that
   * failed its parity check arrives as a valid 0x00; refused (board) with both images when no two agree.
   */
  ics::eeprom_image read_eeprom();
  /**
   * Sets @p changes (ranges checked before anything is read), saving the old image first. A change
   * that makes the servo stop answering (slave on) is refused (usage) unless @p force.
   */
  ics_eeprom_report set_fields(const std::vector<std::pair<ics::field, long>>& changes, const ics_backup& save,
                               bool force = false, bool dry_run = false);
  /**
   * Writes @p image back: refused (board) when its factory bytes are another servo's, and (usage)
   * when it would make the servo stop answering (slave on), unless @p force; refused (usage) when a
   * field is beyond its range and not the servo's value now (a damaged file). The servo's own
   * factory bytes and ID are kept in any case.
   */
  ics_eeprom_report restore(const ics::eeprom_image& image, bool force, const ics_backup& save, bool dry_run = false);

  /** Moves to @p counts (3500-11500); returns where it stood as the command arrived. */
  std::uint16_t move(std::uint16_t counts);
  /** Goes limp; returns the angle where it stopped holding (counts). */
  std::uint16_t free();
  /** Where it stands (ICS 3.6's SC 5); refused (board) by a 3.5 servo, which cannot say without moving. */
  std::uint16_t position();
  /** Reads stretch, speed, current or temperature (SC 1-4). */
  std::uint8_t read(ics::sub what);
  /** Writes stretch, speed, the current limit or the temperature limit (SC 1-4), range checked; the value taken. */
  std::uint8_t write(ics::sub what, long value);

 private:
  template <class Cmd>
  typename Cmd::reply_type ask(const Cmd& c, std::chrono::milliseconds wait, const char* what);
  ics_eeprom_report write_image(const ics::eeprom_image& before, ics::eeprom_image want, const ics_backup& save,
                                bool dry_run);
  ics::eeprom_image read_eeprom_once();  // one read, checked but not verified against another
  ics_link& l_;
  ics::servo_id id_{};
  ics_options o_;
  bool ics36_ = false;   // it has answered the ICS 3.6 position read
  bool echoed_ = false;  // any byte came back (the echo at least): an ICS line
};

/** An ics_link over a port with the same four calls (rcb4::transport::ics_port), kept by the caller. */
template <class Port>
class ics_port_link final : public ics_link {
 public:
  /** Over @p p. */
  explicit ics_port_link(Port& p) : p_(p) {}
  std::vector<std::uint8_t> transact(std::span<const std::uint8_t> request, std::size_t expect,
                                     std::chrono::milliseconds wait) override {
    return p_.transact(request, expect, wait);
  }
  std::vector<std::uint8_t> linger(std::chrono::milliseconds wait) override { return p_.linger(wait); }
  bool last_damaged() const override {
    if constexpr (requires(const Port& q) { q.damaged(); })
      return p_.damaged();
    else
      return false;
  }
  void set_baud(std::uint32_t baud) override { p_.set_baud(baud); }
  std::uint32_t baud() const override { return p_.baud(); }

 private:
  Port& p_;
};

/** An in-process line with virtual servos (the tool without --device, tests, pyrcb4's `IcsServo(None)`). */
class ics_virtual_link final : public ics_link {
 public:
  /** Over @p line, whose servos listen at their own rates; the link starts at 115200. */
  explicit ics_virtual_link(ics::virtual_line line)
      : line_(std::move(line)), start_(std::chrono::steady_clock::now()) {}
  std::vector<std::uint8_t> transact(std::span<const std::uint8_t> request, std::size_t expect,
                                     std::chrono::milliseconds wait) override;
  std::vector<std::uint8_t> linger(std::chrono::milliseconds wait) override;
  void set_baud(std::uint32_t baud) override { baud_ = baud; }
  std::uint32_t baud() const override { return baud_; }
  /** The line and its servos. */
  ics::virtual_line& line() noexcept { return line_; }

 private:
  ics::line_time now() const;
  ics::virtual_line line_;
  std::chrono::steady_clock::time_point start_;
  std::vector<std::uint8_t> pending_;
  std::uint32_t baud_ = 115200;
};

}  // namespace rcb4::robot::services
