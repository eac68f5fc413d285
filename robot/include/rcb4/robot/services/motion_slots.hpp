// rcb4 — robot services: the ROM's motion slots. Push a motion (assemble, back up what it
// overwrites, write, read back), erase one, pull one into a motion file, check one before a play,
// and the refusals a real robot needs before any of it (motions.md §7, protocol.md §4 and §8).
// SPDX-License-Identifier: BSL-1.0
//
//   auto r = push_motion(link, robot, rcb4::hth4_2_2, 10, load_motion("wave.yaml", robot), {}, save_backup);
//   // r.backup: where the slot's old bytes went; r.notes: what the file does that may not be meant
//
// A slot is never written while the board's program could run its bytes: the program counter in
// it, a CALL of it pending on the board's stack (a RETURN would land in it), or a running motion
// that calls it. The call stack itself cannot be read (only its depth, RAM 0x0005, protocol.md §6),
// so its return addresses are bounded from the code: the slots whose CALLs lead to where the
// program counter is. A motion's own calls, through the slots already in ROM, must fit the
// board's 16-deep stack with the play's own CALL (protocol.md §4), and may not call a slot that
// is empty or broken.
#pragma once

#include <rcb4/motion/disassemble.hpp>
#include <rcb4/motion/player.hpp>
#include <rcb4/ops/survey.hpp>
#include <rcb4/robot/motion_file.hpp>
#include <rcb4/robot/services/link.hpp>

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace rcb4::robot::services {

/** Saves a slot's old bytes before a write and returns where they went (the front end's file I/O). */
using backup_sink = std::function<std::string(unsigned motion, std::span<const std::uint8_t> old)>;

/** Writes @p old to @p path, or to motion-N-DATE.bin in the working directory when empty; a refusal names why not. */
std::string save_backup_file(unsigned motion, std::span<const std::uint8_t> old, const std::string& path = {});

/**
 * The bytes of a backup file (a .bin a push or erase saved), read at most one byte past any slot's
 * size, so a wrong or huge file is never read whole; a usage refusal naming it when unreadable.
 * push_motion refuses more bytes than the slot takes.
 */
std::vector<std::uint8_t> read_backup_file(const std::string& path);

/** Motion @p n's slot in @p layout; a usage refusal outside 1..motion_count. */
motion::slot slot_for(const rom_layout& layout, long long n);

/** @p size bytes of ROM from @p at (progress under @p label). */
std::vector<std::uint8_t> read_rom(link& l, std::uint32_t at, std::size_t size, std::string_view label);

/** The bytes of the code the board reaches in @p code (from the slot's start, in address order). */
std::size_t code_size(const motion::listing& code);

/**
 * A program's play time in words, as the board runs it (loops counted): "plays 1.50 s", "plays
 * 2.10 s and 1 call of other motions, no button held", "plays until stopped: ...".
 */
std::string play_time_text(const motion::play_estimate& e, output_period period);

/**
 * How long a slot ops::list_motions walked plays as the board runs it (loops counted, no button
 * held), when it plays (to a RETURN, or round for ever) and its code is one the steps express;
 * nothing otherwise.
 */
std::optional<motion::play_estimate> slot_play_time(const ops::motion_slot& s, const rom_layout& layout);

/** A used slot as the board runs it (the tool's, the studio's and pyrcb4's motion lists). */
struct slot_state {
  std::optional<motion::play_estimate> plays;  ///< its play time (slot_play_time)
  bool endless = false;                        ///< it goes round for ever (a goto loop with no way out)
  /**
   * Why a play of it would stop the board's program ("" when it plays): its first frame is not
   * one (another layout?), a bad frame or no way out (no RETURN, no loop), or a call (through any
   * number of slots) of a slot that is empty or broken.
   */
  std::string problem;
};

/**
 * Each of @p used's slots (ops::list_motions' walk, ascending) as the board runs it, in the same
 * order. A slot's code is followed as the board runs it, so a loop that never reaches a RETURN
 * plays; its calls are followed through @p used.
 */
std::vector<slot_state> slot_states(const std::vector<ops::motion_slot>& used, const rom_layout& layout);

/**
 * @p e's seconds at @p period, to the hundredth; nothing when it goes round for ever, cannot be
 * played, or calls other motions (whose time it does not count).
 */
std::optional<double> play_seconds(const motion::play_estimate& e, output_period period);

/** What a push did. */
struct push_report {
  unsigned motion = 0;              ///< the slot's number
  std::uint32_t address = 0;        ///< its first byte
  std::string layout;               ///< the layout's name
  std::vector<std::uint8_t> bytes;  ///< what was written (or would be, for a dry run)
  bool unchanged = false;           ///< the slot already held them: nothing written
  bool dry_run = false;             ///< checked and assembled only
  std::string backup;               ///< where the slot's old bytes are (empty when nothing was written)
  std::string summary;              ///< "6 steps, 5 poses (plays 1.50 s)", or a .bin's content
  std::string name;                 ///< the name the slot now has (a motion file's name:), or empty
  std::vector<std::string> notes;   ///< what the motion does that may not be meant
  std::uint32_t fingerprint = 0;    ///< code_fingerprint() of the slot now (slot_names.hpp; not for a dry run)
};

/** What a push writes: a motion file's document, or a backup's bytes put back as they are. */
struct push_source {
  std::optional<motion_document> document;  ///< a motion file, read by load_motion
  std::vector<std::uint8_t> bin;            ///< or a slot's bytes (a backup), when no document
  std::string name;                         ///< the file's name, for messages
  bool rescale = false;                     ///< keep the file's times in ms on another output period
};

/**
 * Checks, assembles and writes @p src into motion @p n: refused (nothing written) when it does not
 * assemble, calls an empty or broken slot, nests too deep, or the board's program could run the
 * slot; else the old bytes go to @p backup first, the new ones are written and read back. A write
 * or read-back that fails is refused naming the backup (refused::backup).
 */
push_report push_motion(link& l, const model& robot, const rom_layout& layout, unsigned n, const push_source& src,
                        const backup_sink& backup, bool dry_run = false);

/** What an erase did. */
struct erase_report {
  unsigned motion = 0;            ///< the slot's number
  std::uint32_t address = 0;      ///< its first byte
  std::uint32_t size = 0;         ///< bytes set to 0xFF
  bool unchanged = false;         ///< it was already empty
  std::string backup;             ///< where its old bytes are
  std::vector<unsigned> callers;  ///< the used slots that call it (a play of them now stops the board's program)
};

/**
 * Empties motion @p n (0xFF, as erased ROM reads), its old bytes saved by @p backup first; refused
 * as a push is. With @p robot, the slot's name (slot_names.hpp) is forgotten too.
 */
erase_report erase_motion(link& l, const rom_layout& layout, unsigned n, const backup_sink& backup,
                          const std::string& robot = {});

/** What a pull read. */
struct pull_report {
  unsigned motion = 0;        ///< the slot's number
  std::uint32_t address = 0;  ///< its first byte
  std::string layout;         ///< the layout's name
  std::size_t bytes = 0;      ///< the code's size
  motion_document document;   ///< the motion as a file says it
  std::size_t poses = 0;      ///< poses in it
  long long pose_ms = 0;      ///< their times, summed (one pass)
  std::string plays;          ///< how long it plays as the board runs it, loops counted (play_time_text)
  output_period period{};     ///< the board's output period
  std::string beyond;         ///< why the file would not push back as it is (a pose beyond a limit), or empty
};

/** Reads motion @p n into a document (named from the profile); refused when empty, broken or not expressible. */
pull_report pull_motion(link& l, const model& robot, const rom_layout& layout, unsigned n);

/**
 * Refuses a play of motion @p n (by the host, or by a button) when its slot is empty or broken
 * (a frame that fails its checksum, no RETURN reached): the board would stop its program there.
 * @p what names the play in the message ("UP plays it"; empty: the message starts with the motion).
 */
void require_playable(link& l, const rom_layout& layout, unsigned n, std::string_view what);

/**
 * Refuses code whose calls reach an empty or broken slot, come back round (recursion), or nest
 * (with the play's own CALL) deeper than the board's 16-deep stack, through the code already in
 * ROM. @p code is the code as it will stand in its slot (code.where), @p steps the program it was
 * assembled from and @p where_ each step's "FILE:LINE" (to name the calling step; both optional),
 * @p done what did not happen ("written", "sent").
 */
void check_calls(link& l, const rom_layout& layout, const motion::listing& code, const motion::program* steps,
                 const std::vector<std::string>& where_, std::string_view done);

/**
 * Refuses @p p when one of its poses moves a servo the board has no slot for (the board ignores
 * it, so the pose would not move it); @p done is what did not happen ("written", "sent"). Returns
 * the servos the board has a slot for.
 */
servo_mask require_servo_slots(link& l, const model& robot, const motion::program& p, std::string_view done);

/**
 * Refuses to replace motion @p n (whose bytes now are @p old) while the board's program could run
 * them: see the file comment. @p doing is "written" or "erased".
 */
void require_writable(link& l, const rom_layout& layout, unsigned n, std::span<const std::uint8_t> old,
                      std::string_view doing);

}  // namespace rcb4::robot::services
